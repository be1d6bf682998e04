#include "render/render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <unistd.h>

#include "math/errors.hpp"

namespace arcsim {
namespace {

constexpr int kWidth = 320, kHeight = 240;

// Square [-s, s]^2 in the plane z = height, counter-clockwise seen from +z (its front side).
RenderMesh square(double s, double height = 0) {
  return make_render_mesh({Vec3(-s, -s, height), Vec3(s, -s, height), Vec3(s, s, height), Vec3(-s, s, height)},
                          {{0, 1, 2}, {0, 2, 3}});
}

struct Pixel {
  int r, g, b;
  int luminance() const { return (r + g + b) / 3; }
  // Cloth colours seen under any of our lights: the front is orange (red far above blue), the back blue-grey.
  bool front_colour() const { return r - b > 50; }
  bool back_colour() const { return b - r > 25; }
};

Pixel pixel(const Renderer& renderer, int x, int y) {
  const uint8_t* p = &renderer.rgba()[(size_t(y) * renderer.width() + x) * 4];
  return {p[0], p[1], p[2]};
}

struct Region {
  int count = 0;
  int min_x = 1 << 30, max_x = -1, min_y = 1 << 30, max_y = -1;
};

template <class Predicate>
Region find_region(const Renderer& renderer, Predicate wanted) {
  Region region;
  for (int y = 0; y < renderer.height(); ++y)
    for (int x = 0; x < renderer.width(); ++x)
      if (wanted(pixel(renderer, x, y))) {
        ++region.count;
        region.min_x = std::min(region.min_x, x);
        region.max_x = std::max(region.max_x, x);
        region.min_y = std::min(region.min_y, y);
        region.max_y = std::max(region.max_y, y);
      }
  return region;
}

// A camera looking at the z = 0 plane from the +z side (or the -z side), off-axis so the image is not symmetric.
Camera camera_on_z(double side) {
  Camera camera;
  camera.eye = Vec3(0.7, 0.4, 4 * side);
  camera.target = Vec3(0.1, -0.05, 0);
  camera.up = Vec3::UnitY();
  camera.fov_y_deg = 40;
  return camera;
}

// Plain look for geometry checks: no ground, no antialiasing, y-up world.
RenderOptions plain_options() {
  RenderOptions options;
  options.up = Vec3::UnitY();
  options.ground = false;
  options.samples = 1;
  return options;
}

// One OSMesa context for the whole suite: creating one and compiling its first shaders costs far more than a
// frame.
class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { renderer_ = std::make_unique<Renderer>(kWidth, kHeight); }
  static void TearDownTestSuite() { renderer_.reset(); }
  static std::unique_ptr<Renderer> renderer_;
};
std::unique_ptr<Renderer> RenderTest::renderer_;

TEST_F(RenderTest, SilhouetteMatchesProjectedCorners) {
  const RenderMesh cloth = square(1);
  const Camera camera = camera_on_z(+1);
  RenderOptions options = plain_options();
  for (int samples : {1, 4}) {
    SCOPED_TRACE(::testing::Message() << samples << " samples");
    options.samples = samples;
    options.highlight_edges = false;
    renderer_->render({cloth}, {}, camera, options);
    const Region region = find_region(*renderer_, [](const Pixel& p) { return p.front_colour(); });
    double min_x = kInfinity, max_x = -kInfinity, min_y = kInfinity, max_y = -kInfinity;
    for (const Vec3& corner : cloth.positions) {
      const Vec2 p = project_to_pixel(camera, kWidth, kHeight, corner);
      min_x = std::min(min_x, p.x());
      max_x = std::max(max_x, p.x());
      min_y = std::min(min_y, p.y());
      max_y = std::max(max_y, p.y());
    }
    ASSERT_GT(region.count, 0);
    // Pixel i covers [i, i+1): the covered range is [min, max + 1).
    EXPECT_NEAR(region.min_x, min_x, 2);
    EXPECT_NEAR(region.max_x + 1, max_x, 2);
    EXPECT_NEAR(region.min_y, min_y, 2);
    EXPECT_NEAR(region.max_y + 1, max_y, 2);
    // The square is convex and almost axis-aligned in the image: it fills most of its bounding box.
    EXPECT_GT(region.count, 0.85 * (max_x - min_x) * (max_y - min_y));
  }
}

TEST_F(RenderTest, FrontAndBackSidesHaveDistinctColours) {
  const RenderMesh cloth = square(1);
  renderer_->render({cloth}, {}, camera_on_z(+1), plain_options());
  const Region front_seen_front = find_region(*renderer_, [](const Pixel& p) { return p.front_colour(); });
  const Region back_seen_front = find_region(*renderer_, [](const Pixel& p) { return p.back_colour(); });
  renderer_->render({cloth}, {}, camera_on_z(-1), plain_options());
  const Region front_seen_back = find_region(*renderer_, [](const Pixel& p) { return p.front_colour(); });
  const Region back_seen_back = find_region(*renderer_, [](const Pixel& p) { return p.back_colour(); });
  EXPECT_GT(front_seen_front.count, kWidth * kHeight / 10);
  EXPECT_EQ(back_seen_front.count, 0);
  EXPECT_GT(back_seen_back.count, kWidth * kHeight / 10);
  EXPECT_EQ(front_seen_back.count, 0);
  // Same square, same distance: about the same area either way.
  EXPECT_NEAR(double(back_seen_back.count) / front_seen_front.count, 1.0, 0.1);
}

TEST_F(RenderTest, ObstaclesAreGreyAndDepthTested) {
  // A grey obstacle square in front of (nearer the eye than) the cloth: obstacles are drawn first, so only a
  // depth test keeps the cloth from covering it.
  const RenderMesh cloth = square(1);
  const RenderMesh obstacle = square(0.3, 0.5);
  const Camera camera = camera_on_z(+1);
  renderer_->render({cloth}, {obstacle}, camera, plain_options());
  const Vec2 centre = project_to_pixel(camera, kWidth, kHeight, Vec3(0, 0, 0.5));
  const Pixel p = pixel(*renderer_, int(centre.x()), int(centre.y()));
  EXPECT_LT(std::abs(p.r - p.g), 8);
  EXPECT_LT(std::abs(p.g - p.b), 8);
  EXPECT_GT(p.luminance(), 60);
  const Vec2 cloth_only = project_to_pixel(camera, kWidth, kHeight, Vec3(-0.8, -0.8, 0));
  EXPECT_TRUE(pixel(*renderer_, int(cloth_only.x()), int(cloth_only.y())).front_colour());
}

// Darkest luminance in a (2r+1)^2 window around a projected point.
int darkest_near(const Renderer& renderer, const Camera& camera, const Vec3& point, int r) {
  const Vec2 c = project_to_pixel(camera, renderer.width(), renderer.height(), point);
  int darkest = 255;
  for (int y = int(c.y()) - r; y <= int(c.y()) + r; ++y)
    for (int x = int(c.x()) - r; x <= int(c.x()) + r; ++x)
      if (x >= 0 && y >= 0 && x < renderer.width() && y < renderer.height())
        darkest = std::min(darkest, pixel(renderer, x, y).luminance());
  return darkest;
}

TEST_F(RenderTest, HighlightAndWireframeLinesAreDark) {
  const RenderMesh cloth = square(1);
  const Camera camera = camera_on_z(+1);
  RenderOptions options = plain_options();
  const Vec3 border_midpoint(0, -1, 0), diagonal_midpoint(0.3, 0.3, 0);

  options.highlight_edges = false;
  renderer_->render({cloth}, {}, camera, options);
  const int border_plain = darkest_near(*renderer_, camera, border_midpoint, 2);
  const int diagonal_plain = darkest_near(*renderer_, camera, diagonal_midpoint, 2);
  options.highlight_edges = true;
  renderer_->render({cloth}, {}, camera, options);
  const int border_highlighted = darkest_near(*renderer_, camera, border_midpoint, 2);
  EXPECT_LT(border_highlighted, 80);
  EXPECT_GT(border_plain, 120);
  EXPECT_EQ(darkest_near(*renderer_, camera, diagonal_midpoint, 2), diagonal_plain);  // not a boundary edge
  options.wireframe = true;
  renderer_->render({cloth}, {}, camera, options);
  EXPECT_LT(darkest_near(*renderer_, camera, diagonal_midpoint, 2), diagonal_plain - 30);
}

TEST_F(RenderTest, ShadowFallsWhereTheKeyLightProjectsTheCloth) {
  // A small square hovering above the ground: its shadow is the square slid along the key light onto the ground.
  const RenderMesh cloth = square(0.3, 1.0);
  RenderOptions options;
  options.up = Vec3::UnitZ();
  options.samples = 1;
  options.ground_level = 0;
  options.scene_bounds = Eigen::AlignedBox3d(Vec3(-1, -1, 0), Vec3(1, 1, 1));
  const Camera camera = frame_camera(options.scene_bounds, double(kWidth) / kHeight, options.up);
  const Mat4 shadow = planar_shadow_matrix(Vec3::UnitZ(), 0, key_light_direction(camera, options.up));
  const Vec3 shadow_centre = (shadow * Eigen::Vector4d(0, 0, 1.0, 1)).head<3>();
  EXPECT_NEAR(shadow_centre.z(), 0, 1e-12);
  // Mirror of the shadow centre through the square's foot point: lit ground at the same distance.
  const Vec3 lit_ground(-shadow_centre.x(), -shadow_centre.y(), 0);

  options.shadows = true;
  renderer_->render({cloth}, {}, camera, options);
  const Vec2 s = project_to_pixel(camera, kWidth, kHeight, shadow_centre);
  const Vec2 l = project_to_pixel(camera, kWidth, kHeight, lit_ground);
  const Pixel in_shadow = pixel(*renderer_, int(s.x()), int(s.y()));
  const Pixel lit_with_shadows = pixel(*renderer_, int(l.x()), int(l.y()));
  ASSERT_FALSE(in_shadow.front_colour()) << "the cloth hides its own shadow; move the test camera";
  options.shadows = false;
  renderer_->render({cloth}, {}, camera, options);
  const Pixel no_shadow = pixel(*renderer_, int(s.x()), int(s.y()));
  EXPECT_LT(in_shadow.luminance(), no_shadow.luminance() - 30);
  EXPECT_EQ(pixel(*renderer_, int(l.x()), int(l.y())).luminance(), lit_with_shadows.luminance());
  // The ground is a light neutral grey.
  EXPECT_GT(no_shadow.luminance(), 180);
  EXPECT_LT(std::abs(no_shadow.r - no_shadow.b), 12);
}

TEST_F(RenderTest, OutputIsDeterministic) {
  RenderMesh cloth;
  const int n = 30;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = i / double(n) - 0.5, y = j / double(n) - 0.5;
      cloth.positions.push_back(Vec3(x, y, 0.4 + 0.1 * std::sin(7 * x) * std::cos(5 * y)));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      cloth.triangles.push_back({a, a + 1, a + n + 2});
      cloth.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  cloth.highlight_edges = boundary_edges(cloth.triangles);
  const RenderMesh floor = square(1, 0);
  RenderOptions options;
  options.wireframe = true;
  options.scene_bounds = bounds_of(cloth).extend(bounds_of(floor));
  const Camera camera = frame_camera(options.scene_bounds, double(kWidth) / kHeight, options.up);
  renderer_->render({cloth}, {floor}, camera, options);
  const std::vector<uint8_t> first = renderer_->rgba();
  renderer_->render({square(0.2)}, {}, camera_on_z(1), plain_options());  // something else in between
  renderer_->render({cloth}, {floor}, camera, options);
  EXPECT_EQ(renderer_->rgba(), first);
  Renderer fresh(kWidth, kHeight);
  fresh.render({cloth}, {floor}, camera, options);
  EXPECT_EQ(fresh.rgba(), first);
}

TEST_F(RenderTest, RenderFramePngWritesTheImage) {
  const std::string path = ::testing::TempDir() + "arcsim-render-" + std::to_string(::getpid()) + ".png";
  render_frame_png(*renderer_, {square(1)}, {}, camera_on_z(1), plain_options(), path);
  const Image image = read_png(path);
  EXPECT_EQ(image.width, kWidth);
  EXPECT_EQ(image.height, kHeight);
  EXPECT_EQ(image.rgba, renderer_->rgba());
  std::remove(path.c_str());
}

TEST_F(RenderTest, BadMeshesAreInputErrors) {
  RenderMesh bad = square(1);
  bad.triangles.push_back({0, 1, 7});
  EXPECT_THROW(renderer_->render({bad}, {}, camera_on_z(1), plain_options()), InputError);
  RenderMesh nan = square(1);
  nan.positions[0].x() = std::nan("");
  EXPECT_THROW(renderer_->render({}, {nan}, camera_on_z(1), plain_options()), InputError);
  // The renderer still works afterwards.
  renderer_->render({square(1)}, {}, camera_on_z(1), plain_options());
  EXPECT_GT(find_region(*renderer_, [](const Pixel& p) { return p.front_colour(); }).count, 0);
}

TEST(Renderer, EmptySceneAndBadSizes) {
  EXPECT_THROW(Renderer(0, 10), std::runtime_error);
  EXPECT_THROW(Renderer(10, -1), std::runtime_error);
  EXPECT_THROW(Renderer(100000, 10), std::runtime_error);
  Renderer renderer(16, 8);
  renderer.render({}, {}, Camera(), RenderOptions());
  ASSERT_EQ(renderer.rgba().size(), 16u * 8 * 4);
  // Only background: light, opaque, brighter at the top than at the bottom.
  EXPECT_GT(pixel(renderer, 8, 0).luminance(), 200);
  EXPECT_GE(pixel(renderer, 8, 0).luminance(), pixel(renderer, 8, 7).luminance());
  for (size_t i = 3; i < renderer.rgba().size(); i += 4) EXPECT_EQ(renderer.rgba()[i], 255);
}

}  // namespace
}  // namespace arcsim
