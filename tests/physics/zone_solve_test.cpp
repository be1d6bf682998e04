// Zone physics: the zone solve against the full implicit step with every node outside the zone pinned, on a
// curved, stretched, plastically deformed and damaged sheet with handles, a pinned node, gravity, air drag
// and a contact; the whole mesh as a zone; zones on the border; the empty zone; cost independent of the mesh.
#include <gtest/gtest.h>

#include <algorithm>

#include "physics/zone_fixtures.hpp"
#include "physics/zone_solve.hpp"

namespace arcsim {
namespace {

using testing::ZoneTestSheet;

// The full step of `sheet` with every node outside `zone` pinned (in addition to the loads' own pins).
Mesh full_step_with_outside_pinned(const ZoneTestSheet& sheet, const std::vector<int>& zone, double dt) {
  Mesh mesh = sheet.mesh;
  ExternalLoads loads = sheet.loads;
  std::vector<char> in_zone(mesh.nodes.size(), 0);
  for (int n : zone) in_zone[n] = 1;
  for (size_t n = 0; n < mesh.nodes.size(); ++n)
    if (!in_zone[n]) loads.pinned[n] = 1;
  ElementCache cache;
  build_element_cache(mesh, sheet.materials, cache);
  update_contact_pattern(cache, loads.contacts);
  CholeskySolver solver;
  implicit_euler_step(mesh, cache, solver, loads, dt);
  return mesh;
}

// Largest velocity change of the full step, for relative comparisons.
double largest_dv(const Mesh& before, const Mesh& after) {
  double dv = 0;
  for (size_t n = 0; n < before.nodes.size(); ++n)
    dv = std::max(dv, (after.nodes[n].v - before.nodes[n].v).norm());
  return dv;
}

// Compares a zone solution with the pinned full step: the zone's new v and x, and the nodes left out.
void expect_matches_full_step(const ZoneTestSheet& sheet, const std::vector<int>& zone, double dt) {
  CholeskySolver solver;
  const ZoneSolution zs = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, dt, solver);
  const Mesh full = full_step_with_outside_pinned(sheet, zone, dt);
  const double scale = largest_dv(sheet.mesh, full);
  ASSERT_GT(scale, 0);
  std::vector<int> expected_nodes = zone;
  std::sort(expected_nodes.begin(), expected_nodes.end());
  expected_nodes.erase(std::unique(expected_nodes.begin(), expected_nodes.end()), expected_nodes.end());
  ASSERT_EQ(zs.nodes, expected_nodes);
  for (size_t i = 0; i < zs.nodes.size(); ++i) {
    const Node& f = full.nodes[zs.nodes[i]];
    EXPECT_LT((zs.v[i] - f.v).norm(), 1e-10 * scale) << "node " << zs.nodes[i];
    EXPECT_LT((zs.x[i] - f.x).norm(), 1e-10 * scale * dt) << "node " << zs.nodes[i];
    EXPECT_LT((zs.dv[i] - (f.v - sheet.mesh.nodes[zs.nodes[i]].v)).norm(), 1e-10 * scale);
  }
  // The mesh itself was left untouched (a virtual update).
  const ZoneTestSheet fresh(sheet.cells);
  for (size_t n = 0; n < sheet.mesh.nodes.size(); ++n) {
    EXPECT_EQ(sheet.mesh.nodes[n].x, fresh.mesh.nodes[n].x);
    EXPECT_EQ(sheet.mesh.nodes[n].v, fresh.mesh.nodes[n].v);
  }
}

// A compact zone of about `count` nodes around grid point (i, j): rings around it.
std::vector<int> zone_around(const ZoneTestSheet& sheet, int i, int j, int rings) {
  return node_rings(sheet.mesh, {sheet.node_at(i, j)}, rings);
}

TEST(ZoneSolve, InteriorZoneEqualsFullStepWithOutsidePinned) {
  const ZoneTestSheet sheet(16);
  // Around the contact and reaching the plastic, damaged and curved parts.
  const std::vector<int> zone = zone_around(sheet, 8, 8, 3);
  ASSERT_GT(zone.size(), 20u);
  expect_matches_full_step(sheet, zone, 2e-3);
}

TEST(ZoneSolve, ZoneWithHandleAndPinnedNodeEqualsFullStep) {
  ZoneTestSheet sheet(12);
  // Handle 1 sits at grid (12, 0); the pinned node at (6, 11) is put inside a second zone.
  expect_matches_full_step(sheet, zone_around(sheet, 12, 0, 3), 2e-3);
  expect_matches_full_step(sheet, zone_around(sheet, 6, 11, 2), 2e-3);
}

TEST(ZoneSolve, ZoneOnTheBorderEqualsFullStep) {
  const ZoneTestSheet sheet(12);
  // Along the y = 0 border (boundary edges: bending elements without wings) and a corner.
  std::vector<int> border;
  for (int i = 2; i <= 9; ++i) border.push_back(sheet.node_at(i, 0));
  for (int i = 3; i <= 8; ++i) border.push_back(sheet.node_at(i, 1));
  expect_matches_full_step(sheet, border, 2e-3);
  expect_matches_full_step(sheet, zone_around(sheet, 0, 12, 2), 2e-3);
}

TEST(ZoneSolve, ScatteredZoneEqualsFullStep) {
  const ZoneTestSheet sheet(10);
  // Isolated nodes and pairs: zone nodes whose elements are mostly outside.
  const std::vector<int> zone{sheet.node_at(2, 3), sheet.node_at(7, 7), sheet.node_at(8, 7),
                              sheet.node_at(5, 5), sheet.node_at(5, 5)};
  expect_matches_full_step(sheet, zone, 2e-3);
}

TEST(ZoneSolve, WholeMeshZoneEqualsFullStep) {
  const ZoneTestSheet sheet(10);
  Mesh full = sheet.mesh;
  ElementCache cache;
  build_element_cache(full, sheet.materials, cache);
  update_contact_pattern(cache, sheet.loads.contacts);
  CholeskySolver full_solver;
  const double dt = 2e-3;
  implicit_euler_step(full, cache, full_solver, sheet.loads, dt);

  Mesh zoned = sheet.mesh;
  std::vector<int> all(zoned.nodes.size());
  for (size_t n = 0; n < all.size(); ++n) all[n] = static_cast<int>(n);
  CholeskySolver solver;
  const ZoneSolution zs = zone_implicit_step(zoned, sheet.materials, all, sheet.loads, dt, solver);
  EXPECT_EQ(zs.nodes.size(), all.size());
  EXPECT_EQ(zs.face_elements, static_cast<int>(zoned.faces.size()));
  EXPECT_TRUE(zs.support_nodes.empty());
  const double scale = largest_dv(sheet.mesh, full);
  for (size_t n = 0; n < full.nodes.size(); ++n) {
    EXPECT_LT((zoned.nodes[n].v - full.nodes[n].v).norm(), 1e-10 * scale) << "node " << n;
    EXPECT_LT((zoned.nodes[n].x - full.nodes[n].x).norm(), 1e-10 * scale * dt) << "node " << n;
    EXPECT_LT((zoned.nodes[n].a - full.nodes[n].a).norm(), 1e-10 * scale / dt) << "node " << n;
    EXPECT_EQ(zoned.nodes[n].x0, sheet.mesh.nodes[n].x);
  }
}

TEST(ZoneSolve, EmptyZoneDoesNothing) {
  ZoneTestSheet sheet(6);
  const Mesh before = sheet.mesh;
  CholeskySolver solver;
  const ZoneSolution zs = zone_implicit_step(sheet.mesh, sheet.materials, {}, sheet.loads, 1e-3, solver);
  EXPECT_TRUE(zs.nodes.empty() && zs.support_nodes.empty());
  EXPECT_TRUE(zs.v.empty() && zs.x.empty() && zs.dv.empty());
  EXPECT_EQ(zs.face_elements, 0);
  EXPECT_EQ(solver.analyses(), 0);
  for (size_t n = 0; n < before.nodes.size(); ++n) {
    EXPECT_EQ(sheet.mesh.nodes[n].x, before.nodes[n].x);
    EXPECT_EQ(sheet.mesh.nodes[n].v, before.nodes[n].v);
    EXPECT_EQ(sheet.mesh.nodes[n].x0, before.nodes[n].x0);
  }
}

// A zone of only pinned nodes solves nothing: the nodes keep their velocity and move with it, as in the full
// step.
TEST(ZoneSolve, PinnedOnlyZoneMovesWithItsVelocity) {
  ZoneTestSheet sheet(6);
  const int pinned = sheet.node_at(3, 5);
  ASSERT_TRUE(sheet.loads.pinned[pinned]);
  const Node before = sheet.mesh.nodes[pinned];
  CholeskySolver solver;
  const double dt = 1e-3;
  const ZoneSolution zs = zone_implicit_step(sheet.mesh, sheet.materials, {pinned}, sheet.loads, dt, solver);
  ASSERT_EQ(zs.nodes, std::vector<int>{pinned});
  EXPECT_EQ(zs.face_elements, 0);
  EXPECT_EQ(solver.analyses(), 0);
  EXPECT_EQ(sheet.mesh.nodes[pinned].v, before.v);
  EXPECT_EQ(sheet.mesh.nodes[pinned].x, before.x + dt * before.v);
  EXPECT_EQ(sheet.mesh.nodes[pinned].x0, before.x);
}

TEST(ZoneSolve, SolveLeavesMeshAndApplyWritesOnlyTheZone) {
  ZoneTestSheet sheet(8);
  const Mesh before = sheet.mesh;
  const std::vector<int> zone = zone_around(sheet, 4, 4, 1);
  CholeskySolver solver;
  const double dt = 1e-3;
  const ZoneSolution zs = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, dt, solver);
  for (size_t n = 0; n < before.nodes.size(); ++n) EXPECT_EQ(sheet.mesh.nodes[n].v, before.nodes[n].v);
  apply_zone_solution(sheet.mesh, zs, dt);
  for (size_t n = 0; n < before.nodes.size(); ++n) {
    const bool in_zone = std::binary_search(zs.nodes.begin(), zs.nodes.end(), static_cast<int>(n));
    if (!in_zone) {
      EXPECT_EQ(sheet.mesh.nodes[n].x, before.nodes[n].x);
      EXPECT_EQ(sheet.mesh.nodes[n].v, before.nodes[n].v);
    } else {
      EXPECT_NE(sheet.mesh.nodes[n].v, before.nodes[n].v);
      EXPECT_EQ(sheet.mesh.nodes[n].x0, before.nodes[n].x);
    }
  }
}

// A ZoneSystem solved repeatedly while positions and velocities change (fracture's Newton iterations) gives
// solve_zone's solutions bit for bit, and the solver analyses its pattern once (solve_zone's fresh pattern is
// analysed at every call).
TEST(ZoneSolve, ZoneSystemReusedAcrossIterationsMatchesSolveZone) {
  ZoneTestSheet sheet(12);
  const std::vector<int> zone = zone_around(sheet, 6, 6, 2);
  ZoneSolveOptions options;
  options.linearisation = Linearisation::kNewtonFromRest;
  CholeskySolver kept, fresh;
  const ZoneSystem system(sheet.mesh, sheet.materials, zone, sheet.loads, options);
  const double dt = 1e-3;
  for (int it = 0; it < 3; ++it) {
    SCOPED_TRACE("iteration " + std::to_string(it));
    const ZoneSolution a = system.solve(sheet.mesh, sheet.loads, dt, kept);
    const ZoneSolution b = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, dt, fresh, options);
    ASSERT_EQ(a.nodes, b.nodes);
    EXPECT_EQ(a.support_nodes, b.support_nodes);
    EXPECT_EQ(a.face_elements, b.face_elements);
    EXPECT_EQ(a.bending_elements, b.bending_elements);
    for (size_t i = 0; i < a.nodes.size(); ++i) {
      EXPECT_EQ(a.dv[i], b.dv[i]) << "node " << a.nodes[i];
      EXPECT_EQ(a.x[i], b.x[i]) << "node " << a.nodes[i];
    }
    // The next iterate, as fracture's prediction takes it.
    for (size_t i = 0; i < a.nodes.size(); ++i) {
      Node& n = sheet.mesh.nodes[a.nodes[i]];
      n.v += a.dv[i];
      n.x += dt * a.dv[i];
    }
  }
  EXPECT_EQ(kept.analyses(), 1);
  EXPECT_EQ(fresh.analyses(), 3);
}

// The support is the n-ring around the zone plus the bending wings; with more rings it grows, the solution
// does not change (the support is fixed either way).
TEST(ZoneSolve, SupportRingsAreFixedAndListed) {
  const ZoneTestSheet sheet(12);
  const std::vector<int> zone = zone_around(sheet, 6, 6, 1);
  CholeskySolver solver;
  ZoneSolveOptions one, three;
  one.support_rings = 1;
  three.support_rings = 3;
  const ZoneSolution a = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, 1e-3, solver, one);
  const ZoneSolution b = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, 1e-3, solver, three);
  const std::vector<int> ring1 = node_rings(sheet.mesh, zone, 1), ring3 = node_rings(sheet.mesh, zone, 3);
  for (int n : ring1) {
    if (std::binary_search(zone.begin(), zone.end(), n)) continue;
    EXPECT_TRUE(std::binary_search(a.support_nodes.begin(), a.support_nodes.end(), n)) << n;
  }
  for (int n : a.support_nodes) {
    EXPECT_FALSE(std::binary_search(zone.begin(), zone.end(), n));
    EXPECT_TRUE(std::binary_search(ring3.begin(), ring3.end(), n));  // wings are at most two rings out
  }
  EXPECT_GT(b.support_nodes.size(), a.support_nodes.size());
  EXPECT_EQ(b.support_nodes.size(), ring3.size() - zone.size());
  ASSERT_EQ(a.nodes, b.nodes);
  for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(a.v[i], b.v[i]);
}

// What a zone solve assembles depends on the zone, not on the mesh around it: the same zone (same grid
// neighbourhood) on sheets of 4x the faces assembles the same elements and gives the same system size.
TEST(ZoneSolve, AssembledElementsDoNotGrowWithTheMesh) {
  std::vector<int> faces, bending, support;
  for (int cells : {10, 20, 40}) {
    const ZoneTestSheet sheet(cells);
    const std::vector<int> zone = zone_around(sheet, 5, 5, 3);
    CholeskySolver solver;
    const ZoneSolution zs = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, 1e-3, solver);
    faces.push_back(zs.face_elements);
    bending.push_back(zs.bending_elements);
    support.push_back(static_cast<int>(zs.support_nodes.size()));
    EXPECT_EQ(zs.nodes.size(), zone.size());
  }
  EXPECT_EQ(faces[0], faces[1]);
  EXPECT_EQ(faces[1], faces[2]);
  EXPECT_EQ(bending[0], bending[2]);
  EXPECT_EQ(support[0], support[2]);
}

TEST(ZoneSolve, NodeRingsGrowByEdgeNeighbours) {
  const ZoneTestSheet sheet(6);
  const int centre = sheet.node_at(3, 3);
  EXPECT_EQ(node_rings(sheet.mesh, {centre}, 0), std::vector<int>{centre});
  const std::vector<int> one = node_rings(sheet.mesh, {centre}, 1);
  EXPECT_EQ(one.size(), 1 + sheet.mesh.nodes[centre].edges.size());
  EXPECT_EQ(node_rings(sheet.mesh, {centre}, 20).size(), sheet.mesh.nodes.size());
}

// Newton iterations of the from-rest step (Linearisation::kNewtonFromRest): on an unstressed flat sheet under
// gravity alone the first step is already exact (a rigid translation), so the second iteration, with the
// inertia of the velocity gained in its right-hand side, corrects nothing. The step's linearisation would add
// the same dv again.
TEST(ZoneSolve, NewtonIterationOfAFreeFallCorrectsNothing) {
  Mesh mesh = testing::make_grid(6, 6, 1.0, 1.0, testing::Diagonal::kAlternating);
  std::vector<Material> materials{testing::zone_test_material()};
  for (Face& f : mesh.faces) f.thickness = materials[0].thickness;
  update_node_masses(mesh, materials);
  ExternalLoads loads;
  loads.gravity = Vec3(0, 0, -9.81);
  loads.wind.density = 0;  // no air: its drag at the gained velocity would be a (right) correction
  const double dt = 1e-3;
  std::vector<int> zone;
  for (int n = 0; n < static_cast<int>(mesh.nodes.size()); ++n) zone.push_back(n);
  CholeskySolver solver;
  const ZoneSolution first = solve_zone(mesh, materials, zone, loads, dt, solver);
  for (size_t i = 0; i < first.nodes.size(); ++i) {
    EXPECT_LT((first.dv[i] - dt * loads.gravity).norm(), 1e-12);
    mesh.nodes[first.nodes[i]].v = first.dv[i];
    mesh.nodes[first.nodes[i]].x += dt * first.dv[i];
  }
  ZoneSolveOptions options;
  options.linearisation = Linearisation::kNewtonFromRest;
  const ZoneSolution second = solve_zone(mesh, materials, zone, loads, dt, solver, options);
  for (size_t i = 0; i < second.nodes.size(); ++i) EXPECT_LT(second.dv[i].norm(), 1e-12) << "node " << i;
}

// On the stretched, curved, waved test sheet (nonlinear elasticity, damping, air drag, handle springs) the
// iterations converge to the backward Euler step from rest, at a step where inertia dominates (1e-4 s: each
// correction about 1% of the one before). At 1e-2 s they still contract, but slowly (about 0.5 per
// iteration: the projected Hessians are not the exact ones); fracture stops iterating when a correction grows.
TEST(ZoneSolve, NewtonIterationsOfTheStepFromRestConverge) {
  ZoneTestSheet sheet(8);
  Mesh& mesh = sheet.mesh;
  for (Node& n : mesh.nodes) n.v.setZero();
  sheet.loads.contacts.clear();
  const double dt = 1e-4;
  std::vector<int> zone;
  for (int n = 0; n < static_cast<int>(mesh.nodes.size()); ++n) zone.push_back(n);
  std::vector<Vec3> start(mesh.nodes.size());
  for (size_t n = 0; n < mesh.nodes.size(); ++n) start[n] = mesh.nodes[n].x;
  CholeskySolver solver;
  std::vector<double> corrections;
  for (int it = 0; it < 5; ++it) {
    ZoneSolveOptions options;
    options.linearisation = Linearisation::kNewtonFromRest;
    const ZoneSolution sol = solve_zone(mesh, sheet.materials, zone, sheet.loads, dt, solver, options);
    double largest = 0;
    for (size_t i = 0; i < sol.nodes.size(); ++i) {
      const int n = sol.nodes[i];
      mesh.nodes[n].v += sol.dv[i];
      mesh.nodes[n].x = start[n] + dt * mesh.nodes[n].v;
      largest = std::max(largest, sol.dv[i].norm());
    }
    corrections.push_back(largest);
  }
  ASSERT_GT(corrections[0], 0);
  EXPECT_GT(corrections[1], 1e-6 * corrections[0]) << "the problem is linear: the test proves nothing";
  for (int it = 1; it < 5; ++it) EXPECT_LT(corrections[it], 0.05 * corrections[it - 1]) << "iteration " << it;
}

}  // namespace
}  // namespace arcsim
