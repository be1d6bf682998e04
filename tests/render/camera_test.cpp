#include "render/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace arcsim {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(RenderCamera, ProjectsWithPinholeGeometry) {
  // 90 degree vertical field of view: tan(45 deg) = 1, so a point at lateral offset x and depth d lands at
  // normalised x / (d * aspect) horizontally and y / d vertically.
  Camera camera;
  camera.eye = Vec3(0, 0, 5);
  camera.target = Vec3::Zero();
  camera.up = Vec3::UnitY();
  camera.fov_y_deg = 90;
  const int w = 200, h = 100;
  const Vec2 centre = project_to_pixel(camera, w, h, Vec3::Zero());
  EXPECT_NEAR(centre.x(), 100, 1e-9);
  EXPECT_NEAR(centre.y(), 50, 1e-9);
  const Vec2 right = project_to_pixel(camera, w, h, Vec3(1, 0, 0));  // 1/(5*2) = 0.1 of the half-width
  EXPECT_NEAR(right.x(), 110, 1e-9);
  EXPECT_NEAR(right.y(), 50, 1e-9);
  const Vec2 up = project_to_pixel(camera, w, h, Vec3(0, 1, 0));     // rows grow downwards
  EXPECT_NEAR(up.x(), 100, 1e-9);
  EXPECT_NEAR(up.y(), 40, 1e-9);
  const Vec2 nearer = project_to_pixel(camera, w, h, Vec3(1, 1, 3));  // depth 2
  EXPECT_NEAR(nearer.x(), 100 + 100 * 0.25, 1e-9);
  EXPECT_NEAR(nearer.y(), 50 - 50 * 0.5, 1e-9);
}

TEST(RenderCamera, PointsBehindTheEyeAreInfinite) {
  Camera camera;
  camera.eye = Vec3(0, 0, 5);
  camera.target = Vec3::Zero();
  camera.up = Vec3::UnitY();
  EXPECT_FALSE(project_to_pixel(camera, 64, 64, Vec3(0, 0, 6)).allFinite());
  EXPECT_FALSE(project_to_pixel(camera, 64, 64, Vec3(0.3, 0, 5)).allFinite());
}

TEST(RenderCamera, FrameIsOrthonormalEvenWhenLookingAlongUp) {
  Camera camera;
  camera.eye = Vec3(0, 0, 4);
  camera.target = Vec3::Zero();
  camera.up = Vec3::UnitZ();  // parallel to the view direction
  const CameraFrame f = camera_frame(camera);
  EXPECT_NEAR(f.right.norm(), 1, 1e-12);
  EXPECT_NEAR(f.up.norm(), 1, 1e-12);
  EXPECT_NEAR(f.right.dot(f.up), 0, 1e-12);
  EXPECT_NEAR(f.right.cross(f.up).dot(f.back), 1, 1e-12);
  EXPECT_TRUE(project_to_pixel(camera, 64, 64, Vec3(0.1, 0.2, 0)).allFinite());
}

TEST(RenderCamera, UpFromGravity) {
  EXPECT_TRUE(up_from_gravity(Vec3(0, 0, -9.8)).isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(up_from_gravity(Vec3(0, -9.8, 0)).isApprox(Vec3::UnitY()));
  EXPECT_TRUE(up_from_gravity(Vec3(9.81, 0, 0)).isApprox(-Vec3::UnitX()));
  EXPECT_TRUE(up_from_gravity(Vec3::Zero()).isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(up_from_gravity(Vec3(std::nan(""), 0, 0)).isApprox(Vec3::UnitZ()));
}

struct FramingCase {
  Eigen::AlignedBox3d box;
  double aspect;
  Vec3 up;
};

// Every corner inside the image, and the fit is snug: the box reaches at least 70% of the way to the border on
// some side (a camera far away would pass the first check trivially).
void expect_framed(const FramingCase& c) {
  const int h = 400, w = int(std::lround(400 * c.aspect));
  const Camera camera = frame_camera(c.box, double(w) / h, c.up);
  double min_x = kInfinity, max_x = -kInfinity, min_y = kInfinity, max_y = -kInfinity;
  for (int i = 0; i < 8; ++i) {
    const Vec2 p = project_to_pixel(camera, w, h, c.box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)));
    ASSERT_TRUE(p.allFinite());
    EXPECT_GE(p.x(), 0);
    EXPECT_LE(p.x(), w);
    EXPECT_GE(p.y(), 0);
    EXPECT_LE(p.y(), h);
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
    min_y = std::min(min_y, p.y());
    max_y = std::max(max_y, p.y());
  }
  const double used = std::max((max_x - min_x) / w, (max_y - min_y) / h);
  EXPECT_GT(used, 0.7) << "box uses only " << used << " of the image";
  // Roughly centred.
  EXPECT_NEAR((min_x + max_x) / 2, w / 2.0, 0.1 * w);
  EXPECT_NEAR((min_y + max_y) / 2, h / 2.0, 0.1 * h);
  // Elevated: the eye is above the box centre.
  EXPECT_GT((camera.eye - c.box.center()).dot(c.up.normalized()), 0);
}

TEST(RenderCamera, FrameCameraKeepsAllCornersInside) {
  const Eigen::AlignedBox3d cube(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  const Eigen::AlignedBox3d sheet(Vec3(0, 0, 0.5), Vec3(2, 1, 0.5));       // flat, off-centre
  const Eigen::AlignedBox3d hanging(Vec3(-0.5, 0, -1), Vec3(0.5, 0, 0));   // vertical flag
  const Eigen::AlignedBox3d tall(Vec3(10, 10, 0), Vec3(10.2, 10.3, 5));
  const std::vector<FramingCase> cases = {
      {cube, 16.0 / 9, Vec3::UnitZ()},    {cube, 0.5, Vec3::UnitY()},        {sheet, 16.0 / 9, Vec3::UnitZ()},
      {sheet, 1.0, Vec3::UnitY()},        {hanging, 16.0 / 9, Vec3::UnitZ()}, {tall, 16.0 / 9, Vec3::UnitZ()},
      {tall, 16.0 / 9, -Vec3::UnitX()}};
  for (const FramingCase& c : cases) {
    SCOPED_TRACE(::testing::Message() << "box " << c.box.min().transpose() << " / " << c.box.max().transpose()
                                      << " aspect " << c.aspect << " up " << c.up.transpose());
    expect_framed(c);
  }
}

TEST(RenderCamera, FrameCameraLooksFromTheFrontSideAtThreeQuarters) {
  const Eigen::AlignedBox3d cube(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  const Camera z_up = frame_camera(cube, 1.5, Vec3::UnitZ());
  const Vec3 d = (z_up.eye - z_up.target).normalized();
  EXPECT_LT(d.y(), -0.5);  // z-up scenes are seen from -y ...
  EXPECT_GT(d.x(), 0.2);   // ... turned towards +x ...
  EXPECT_NEAR(std::asin(d.z()) * 180 / kPi, FramingOptions().elevation_deg, 1e-6);  // ... from above
  const Camera y_up = frame_camera(cube, 1.5, Vec3::UnitY());
  EXPECT_GT((y_up.eye - y_up.target).normalized().z(), 0.5);  // y-up scenes from +z
}

TEST(RenderCamera, FrameCameraSurvivesDegenerateBounds) {
  for (const Eigen::AlignedBox3d& box :
       {Eigen::AlignedBox3d(), Eigen::AlignedBox3d(Vec3(1, 2, 3), Vec3(1, 2, 3)),
        Eigen::AlignedBox3d(Vec3(0, 0, 0), Vec3(kInfinity, 1, 1))}) {
    const Camera camera = frame_camera(box, 0, Vec3::Zero());
    EXPECT_TRUE(camera.eye.allFinite());
    EXPECT_TRUE(camera.target.allFinite());
    EXPECT_GT((camera.eye - camera.target).norm(), 0);
  }
  // A point is framed as a small box around it (centred in the image up to perspective).
  const Camera camera = frame_camera(Eigen::AlignedBox3d(Vec3(1, 2, 3), Vec3(1, 2, 3)), 1.0);
  const Vec2 p = project_to_pixel(camera, 100, 100, Vec3(1, 2, 3));
  EXPECT_NEAR(p.x(), 50, 15);
  EXPECT_NEAR(p.y(), 50, 15);
}

}  // namespace
}  // namespace arcsim
