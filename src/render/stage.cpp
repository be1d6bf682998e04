#include "render/stage.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

namespace {

Vec3 unit_or(const Vec3& v, const Vec3& fallback) {
  const double n = v.norm();
  return std::isfinite(n) && n > 1e-300 ? Vec3(v / n) : fallback;
}

Eigen::AlignedBox3d usable_box(const Eigen::AlignedBox3d& box) {
  if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite())
    return Eigen::AlignedBox3d(Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  return box;
}

}  // namespace

double lowest_level(const Eigen::AlignedBox3d& box, const Vec3& up) {
  double lowest = kInfinity;
  for (int i = 0; i < 8; ++i)
    lowest = std::min(lowest, up.dot(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i))));
  return lowest;
}

Vec3 key_light_direction(const Camera& camera, const Vec3& up) {
  const Vec3 u = unit_or(up, Vec3::UnitZ());
  const CameraFrame frame = camera_frame(camera);
  const HorizontalAxes axes = horizontal_axes(u);
  const Vec3 toward_viewer = unit_or(frame.back - u * u.dot(frame.back), axes.front);
  const Vec3 viewer_right = u.cross(toward_viewer);
  return (1.7 * u + 0.55 * toward_viewer - 0.6 * viewer_right).normalized();
}

Stage make_stage(const Camera& camera, const Vec3& up, const Eigen::AlignedBox3d& scene_bounds, double ground_level) {
  Stage stage;
  stage.up = unit_or(up, Vec3::UnitZ());
  const Eigen::AlignedBox3d box = usable_box(scene_bounds);
  stage.ground_level = std::isfinite(ground_level) ? ground_level : lowest_level(box, stage.up);
  stage.scene_radius = std::max(box.diagonal().norm() / 2, 1e-3);
  const Vec3 center = box.center();
  stage.ground_center = center - stage.up * (stage.up.dot(center) - stage.ground_level);
  stage.ground_radius = 3 * stage.scene_radius;
  stage.key_light = key_light_direction(camera, stage.up);
  stage.fill_light = unit_or(camera_frame(camera).back + 0.3 * stage.up, stage.up);
  return stage;
}

Mat4 planar_shadow_matrix(const Vec3& normal, double level, const Vec3& toward_light) {
  // p' = p - L (n.p - level) / (n.L): slide p along the light direction until it meets the plane.
  const double n_dot_l = normal.dot(toward_light);
  Mat4 m = Mat4::Identity();
  m.block<3, 3>(0, 0) -= toward_light * normal.transpose() / n_dot_l;
  m.block<3, 1>(0, 3) = toward_light * level / n_dot_l;
  return m;
}

double checker_cell_size(double scene_radius) {
  const double target = std::isfinite(scene_radius) && scene_radius > 0 ? scene_radius / 3 : 0.3;
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  for (double step : {5.0, 2.0, 1.0})
    if (step * decade <= target) return step * decade;
  return decade;
}

}  // namespace arcsim
