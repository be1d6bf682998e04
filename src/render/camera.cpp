#include "render/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace arcsim {

namespace {

constexpr double kPi = 3.14159265358979323846;

double radians(double degrees) { return degrees * kPi / 180.0; }

// Field of view kept away from 0 and 180 degrees, where the projection degenerates.
double safe_fov_y_deg(double fov_y_deg) {
  if (!std::isfinite(fov_y_deg)) return 35;
  return std::clamp(fov_y_deg, 1.0, 170.0);
}

double safe_aspect(double aspect) { return std::isfinite(aspect) && aspect > 0 ? aspect : 1.0; }

Vec3 unit_or(const Vec3& v, const Vec3& fallback) {
  const double n = v.norm();
  return std::isfinite(n) && n > 1e-300 ? Vec3(v / n) : fallback;
}

}  // namespace

Vec3 up_from_gravity(const Vec3& gravity) { return unit_or(-gravity, Vec3::UnitZ()); }

CameraFrame camera_frame(const Camera& camera) {
  const Vec3 world_up = unit_or(camera.up, Vec3::UnitZ());
  CameraFrame frame;
  frame.back = unit_or(camera.eye - camera.target, horizontal_axes(world_up).front);
  Vec3 right = world_up.cross(frame.back);
  // Looking straight along `up`: any right vector perpendicular to the view direction will do.
  frame.right = right.norm() > 1e-9 ? Vec3(right.normalized()) : Vec3(frame.back.unitOrthogonal());
  frame.up = frame.back.cross(frame.right);
  return frame;
}

Mat4 view_matrix(const Camera& camera) {
  const CameraFrame f = camera_frame(camera);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = f.right.transpose();
  m.block<1, 3>(1, 0) = f.up.transpose();
  m.block<1, 3>(2, 0) = f.back.transpose();
  m.block<3, 1>(0, 3) = -m.block<3, 3>(0, 0) * camera.eye;
  return m;
}

Mat4 projection_matrix(const Camera& camera, double aspect, double z_near, double z_far) {
  const double f = 1.0 / std::tan(radians(safe_fov_y_deg(camera.fov_y_deg)) / 2);
  Mat4 m = Mat4::Zero();
  m(0, 0) = f / safe_aspect(aspect);
  m(1, 1) = f;
  m(2, 2) = (z_far + z_near) / (z_near - z_far);
  m(2, 3) = 2 * z_far * z_near / (z_near - z_far);
  m(3, 2) = -1;
  return m;
}

Vec2 project_to_pixel(const Camera& camera, int width, int height, const Vec3& p) {
  const Vec3 e = (view_matrix(camera) * p.homogeneous()).head<3>();
  const double depth = -e.z();  // distance in front of the eye along the view direction (m)
  if (!(depth > 0)) return Vec2(kInfinity, kInfinity);
  const double f = 1.0 / std::tan(radians(safe_fov_y_deg(camera.fov_y_deg)) / 2);
  const double aspect = safe_aspect(double(width) / double(height));
  const double ndc_x = f / aspect * e.x() / depth, ndc_y = f * e.y() / depth;
  return Vec2((ndc_x + 1) / 2 * width, (1 - ndc_y) / 2 * height);
}

HorizontalAxes horizontal_axes(const Vec3& up) {
  const Vec3 u = unit_or(up, Vec3::UnitZ());
  // z-up scenes are viewed from -y, all others from +z (the usual OpenGL viewer position for y-up scenes).
  const Vec3 preferred = std::abs(u.z()) > 0.8 ? Vec3(-Vec3::UnitY()) : Vec3(Vec3::UnitZ());
  HorizontalAxes axes;
  axes.front = unit_or(preferred - u * u.dot(preferred), u.unitOrthogonal());
  axes.side = u.cross(axes.front);
  return axes;
}

Camera frame_camera(const Eigen::AlignedBox3d& bounds, double aspect, const Vec3& up,
                    const FramingOptions& options) {
  Eigen::AlignedBox3d box = bounds;
  if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite())
    box = Eigen::AlignedBox3d(Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  const Vec3 center = box.center();
  // A point-like box would put the eye on the target: give it a small size instead.
  double radius = box.diagonal().norm() / 2;
  if (radius < 1e-6) {
    box.extend(center + Vec3::Constant(0.05));
    box.extend(center - Vec3::Constant(0.05));
    radius = box.diagonal().norm() / 2;
  }

  Camera camera;
  camera.up = unit_or(up, Vec3::UnitZ());
  camera.fov_y_deg = safe_fov_y_deg(options.fov_y_deg);
  const HorizontalAxes axes = horizontal_axes(camera.up);
  const double az = radians(options.azimuth_deg), el = radians(options.elevation_deg);
  const Vec3 back = unit_or(std::cos(el) * (std::cos(az) * axes.front + std::sin(az) * axes.side) +
                                std::sin(el) * camera.up,
                            axes.front);
  camera.target = center;
  camera.eye = center + back;  // direction only for now; the distance is fitted below
  const CameraFrame frame = camera_frame(camera);

  const double fill = std::isfinite(options.fill) ? std::clamp(options.fill, 0.1, 1.0) : 0.9;
  const double tan_y = std::tan(radians(camera.fov_y_deg) / 2);
  const double tan_x = tan_y * safe_aspect(aspect);
  std::array<Vec3, 8> corners;
  for (int i = 0; i < 8; ++i) corners[i] = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i));

  // Moving the eye along `back` leaves a corner's image-plane offsets from the target unchanged and only changes
  // its depth (distance - s), so each corner gives a lower bound on the distance from the target.
  auto fitted_distance = [&](const Vec3& target) {
    double distance = 0;
    for (const Vec3& corner : corners) {
      const Vec3 q = corner - target;
      const double s = q.dot(frame.back);
      const double need = std::max({std::abs(q.dot(frame.right)) / (fill * tan_x),
                                    std::abs(q.dot(frame.up)) / (fill * tan_y), 0.05 * radius});
      distance = std::max(distance, s + need);
    }
    return distance;
  };
  // Perspective makes the box's image lopsided around its centre; slide the target sideways until the image is
  // centred, which lets the final fit come closer. The last fit bounds every corner whatever the target.
  for (int iteration = 0; iteration < 4; ++iteration) {
    const Vec3 eye = camera.target + fitted_distance(camera.target) * frame.back;
    Eigen::AlignedBox2d image;
    for (const Vec3& corner : corners) {
      const Vec3 q = corner - eye;
      const double depth = -q.dot(frame.back);
      image.extend(Vec2(q.dot(frame.right) / (depth * tan_x), q.dot(frame.up) / (depth * tan_y)));
    }
    const double target_depth = (camera.target - eye).norm();
    camera.target +=
        target_depth * (image.center().x() * tan_x * frame.right + image.center().y() * tan_y * frame.up);
  }
  const double distance = fitted_distance(camera.target);
  camera.eye = camera.target + distance * frame.back;
  return camera;
}

}  // namespace arcsim
