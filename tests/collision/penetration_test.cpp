// The tests' penetration check (penetration.hpp): winding numbers and depths against a sphere and an open
// sheet whose answers are known in closed form.
#include <gtest/gtest.h>

#include "collision/penetration.hpp"
#include "collision/scene_fixtures.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using namespace testing;

TEST(Penetration, DepthInsideAClosedSphere) {
  const Mesh sphere = make_sphere(1.0, 2);
  const ObstacleSurface s(sphere);
  ASSERT_TRUE(s.closed());
  EXPECT_NEAR(s.winding_number(Vec3(0.1, 0.2, -0.3)), 1.0, 1e-9);
  EXPECT_NEAR(s.winding_number(Vec3(1.5, 0.2, 0)), 0.0, 1e-9);
  // Halfway to the surface: depth about 0.5 (the polyhedron is within 5% of the sphere).
  EXPECT_NEAR(s.depth(Vec3(0.5, 0, 0)), 0.5, 0.05);
  EXPECT_EQ(s.depth(Vec3(0, 1.2, 0)), 0.0);
  // Just inside a face's centre: the depth is the distance to that face's plane.
  const auto t = world_triangle(sphere, 7);
  const Vec3 centre = (t[0] + t[1] + t[2]) / 3, normal = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  EXPECT_NEAR(s.depth(centre - 2e-4 * normal), 2e-4, 1e-12);
  EXPECT_EQ(s.depth(centre + 2e-4 * normal), 0.0);
}

TEST(Penetration, OpenSheetHasNoInsideButFloorProxyHas) {
  const Mesh sheet = make_grid(2, 2, 1, 1);
  const ObstacleSurface s(sheet);
  EXPECT_FALSE(s.closed());
  EXPECT_EQ(s.depth(Vec3(0.5, 0.5, -0.1)), 0.0);
  EXPECT_NEAR(s.distance(Vec3(0.5, 0.5, -0.1)), 0.1, 1e-12);
}

}  // namespace
}  // namespace arcsim
