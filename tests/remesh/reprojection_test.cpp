// Local world-space reprojection (paper Eq. 13): a displaced node returns to equilibrium with its fixed
// neighbours, and the m (a - g) . x term makes its elastic force balance m (a - g).
#include <gtest/gtest.h>

#include "remesh/remesh_fixtures.hpp"
#include "remesh/reprojection.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using remesh_test::cotton;
using remesh_test::set_thickness;

// The node nearest the middle of a grid.
int middle_node(const Mesh& m, const Vec3& centre) {
  int best = 0;
  for (size_t n = 0; n < m.nodes.size(); ++n)
    if ((m.nodes[n].x - centre).norm() < (m.nodes[best].x - centre).norm()) best = static_cast<int>(n);
  return best;
}

TEST(Reprojection, InPlaneDisplacementReturnsToRest) {
  Mesh m = testing::make_grid(6, 6, 0.6, 0.6);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const int n = middle_node(m, Vec3(0.3, 0.3, 0));
  const Vec3 rest = m.nodes[n].x;
  m.nodes[n].x += Vec3(0.03, -0.02, 0);
  m.nodes[n].x0 = m.nodes[n].x;
  const ReprojectionResult r = reproject_node(m, materials, n, {});
  EXPECT_TRUE(r.moved);
  EXPECT_LT(r.energy_after, 1e-12 * r.energy_before);
  EXPECT_LT((m.nodes[n].x - rest).norm(), 1e-9);
  EXPECT_LT((m.nodes[n].x0 - rest).norm(), 1e-9);  // x0 moves with x
}

TEST(Reprojection, OutOfPlaneDisplacementShrinks) {
  // Out of plane a flat sheet's membrane energy is quartic, so Newton converges linearly there: the node must
  // come most of the way back in the default 10 iterations, with the energy decreasing.
  Mesh m = testing::make_grid(6, 6, 0.6, 0.6);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const int n = middle_node(m, Vec3(0.3, 0.3, 0));
  m.nodes[n].x.z() += 0.02;
  const ReprojectionResult r = reproject_node(m, materials, n, {});
  EXPECT_LT(r.energy_after, 0.01 * r.energy_before);
  EXPECT_LT(std::abs(m.nodes[n].x.z()), 0.1 * 0.02);
}

TEST(Reprojection, MotionAcrossTheSheetIsLimitedInPlaneMotionIsNot) {
  // The node is 20 mm above a flat sheet and 30 mm off in the plane. With a 2 mm limit across the sheet it
  // moves exactly 2 mm across (never further, which could cross a nearby layer), while its in-plane offset
  // still relaxes; the energy still decreases.
  Mesh m = testing::make_grid(6, 6, 0.6, 0.6);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const int n = middle_node(m, Vec3(0.3, 0.3, 0));
  const Vec3 rest = m.nodes[n].x;
  m.nodes[n].x += Vec3(0.03, 0, 0.02);
  ReprojectionParams params;
  params.max_displacement = 0.002;
  const Vec3 start = m.nodes[n].x;
  // "Across" is the mean world normal of the node's faces at the start.
  Vec3 normal = Vec3::Zero();
  for (size_t f = 0; f < m.faces.size(); ++f)
    for (int i = 0; i < 3; ++i)
      if (m.face_node(static_cast<int>(f), i) == n) normal += m.world_normal(static_cast<int>(f));
  normal.normalize();
  const ReprojectionResult r = reproject_node(m, materials, n, params);
  EXPECT_TRUE(r.moved);
  EXPECT_LT(r.energy_after, r.energy_before);
  const Vec3 moved = m.nodes[n].x - start;
  EXPECT_LE(std::abs(moved.dot(normal)), 0.002 * (1 + 1e-9));
  EXPECT_GT(std::abs(moved.dot(normal)), 0.0019);  // the limit is what stopped it
  EXPECT_LT(std::abs(m.nodes[n].x.x() - rest.x()), 0.5 * 0.03);
}

TEST(Reprojection, AccelerationTermBalancesElasticForce) {
  // A pre-stretched sheet (so it has out-of-plane stiffness); the node had acceleration a = -5 m/s^2 along z.
  // At the minimiser the elastic force equals m a: the node sits above the plane, pulled down by its
  // neighbours. With gravity equal to a, m (a - g) = 0 and the node stays in the plane.
  Mesh m = testing::make_grid(6, 6, 0.6, 0.6);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  for (Node& node : m.nodes) node.x *= 1.01;
  const int n = middle_node(m, Vec3(0.3, 0.3, 0));
  m.nodes[n].a = Vec3(0, 0, -5);
  Mesh same = m;
  ReprojectionParams params;
  params.max_iterations = 50;
  reproject_node(m, materials, n, params);
  EXPECT_GT(m.nodes[n].x.z(), 1e-7);
  const LocalEnergy with_load = node_local_energy(m, materials, n, m.nodes[n].x, params);
  Mesh unloaded = m;
  unloaded.nodes[n].a.setZero();
  const Vec3 load = with_load.gradient - node_local_energy(unloaded, materials, n, m.nodes[n].x, params).gradient;
  double mass = 0;  // lumped: a third of each incident face's mass
  for (const Face& f : m.faces)
    for (int i = 0; i < 3; ++i)
      if (m.verts[f.v[i]].node == n) mass += materials[0].area_density(f.thickness) * f.rest_area / 3;
  EXPECT_NEAR(load.z(), -5 * mass, 1e-12);
  EXPECT_LT(with_load.gradient.norm(), 1e-6 * load.norm());

  params.gravity = Vec3(0, 0, -5);
  const Vec3 before = same.nodes[n].x;
  reproject_node(same, materials, n, params);
  EXPECT_LT((same.nodes[n].x - before).norm(), 1e-9);
}

}  // namespace
}  // namespace arcsim
