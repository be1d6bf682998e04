// The remeshing guard: edits may not make the world surface cross an obstacle or itself (remesh/world_guard).
// A tent-shaped sheet (centre node raised) covers a small obstacle plate; coarsening wants to collapse the
// centre, which would flatten the tent through the plate (or past it: the plate is small enough to end up
// outside, uncrossed, which is as wrong). With the guard the plate stays under the sheet and clear of it;
// without it the same pass crosses it or leaves it outside (so the test can tell).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "collision/triangle_intersection.hpp"
#include "mesh/validate.hpp"
#include "remesh/remesh.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "remesh/world_guard.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using remesh_test::cotton;
using remesh_test::set_thickness;

constexpr double kApex = 0.1;  // m, height of the tent's centre; the flattened tent lies at half of it

Mesh tent() {
  Mesh m = testing::make_grid(4, 4, 1.0, 1.0);
  for (Node& n : m.nodes) {
    const double r = std::max(std::abs(n.x.x() - 0.5), std::abs(n.x.y() - 0.5));
    n.x.z() = n.x0.z() = kApex * std::max(0.0, 1 - 2 * r);
  }
  return m;
}

// A small horizontal plate under the apex, above the height the flattened tent would have.
Mesh plate() {
  const double z = 0.75 * kApex;
  return remesh_test::mesh_from({Vec3(0.47, 0.47, z), Vec3(0.53, 0.47, z), Vec3(0.5, 0.53, z)}, {{0, 1, 2}});
}

// The plate is inside the tent: below the sheet over its centre.
bool plate_under_sheet(const Mesh& sheet) {
  for (size_t f = 0; f < sheet.faces.size(); ++f) {
    if (sheet.faces[f].dead) continue;
    std::array<Vec3, 3> x;
    for (int i = 0; i < 3; ++i) x[i] = sheet.nodes[sheet.face_node(static_cast<int>(f), i)].x;
    // Vertical ray up from the plate's centre.
    const Vec3 p(0.5, 0.49, 0.75 * kApex);
    const Vec3 n = (x[1] - x[0]).cross(x[2] - x[0]);
    if (n.z() == 0) continue;
    const double t = n.dot(x[0] - p) / n.z();
    const Vec3 q = p + t * Vec3::UnitZ();
    bool inside = true;
    for (int i = 0; i < 3; ++i) inside = inside && n.dot((x[(i + 1) % 3] - x[i]).cross(q - x[i])) >= 0;
    if (inside) return t > 0;
  }
  return false;
}

int crossings(const Mesh& sheet, const Mesh& obstacle) {
  int n = 0;
  for (size_t f = 0; f < sheet.faces.size(); ++f) {
    if (sheet.faces[f].dead) continue;
    std::array<Vec3, 3> a, b;
    for (int i = 0; i < 3; ++i) {
      a[i] = sheet.nodes[sheet.face_node(static_cast<int>(f), i)].x;
      b[i] = obstacle.nodes[obstacle.face_node(0, i)].x;
    }
    n += triangles_intersect(a, b);
  }
  return n;
}

RemeshStats coarsen(Mesh& m, const Mesh& obstacle, double clearance) {
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  RemeshOptions o;
  o.extras.uniform_size = 10;    // every interior node is a collapse candidate
  o.max_surface_change = 0;      // only the guard stands between the tent and the plate
  o.reproject = false;
  o.world_clearance = clearance;
  o.obstacles = {&obstacle};
  return remesh_mesh(m, materials, o);
}

TEST(WorldGuard, CoarseningDoesNotFlattenTheSheetThroughAnObstacle) {
  const Mesh obstacle = plate();
  Mesh unguarded = tent();
  ASSERT_EQ(crossings(unguarded, obstacle), 0);
  const RemeshStats free = coarsen(unguarded, obstacle, 0);
  EXPECT_GT(free.collapses, 0);
  EXPECT_TRUE(crossings(unguarded, obstacle) > 0 || !plate_under_sheet(unguarded))
      << "the unguarded pass should cross the plate or leave it outside";

  Mesh guarded = tent();
  const RemeshStats s = coarsen(guarded, obstacle, 1e-4);
  EXPECT_EQ(check_mesh(guarded), "");
  EXPECT_GT(s.collapses, 0) << "edits away from the plate still happen";
  EXPECT_GT(s.guarded, 0);
  EXPECT_EQ(crossings(guarded, obstacle), 0);
  EXPECT_TRUE(plate_under_sheet(guarded));
  // The plate keeps the clearance from the sheet.
  const WorldGuard probe(guarded, {}, 1.0);
  std::vector<GuardTriangle> plate_triangle(1);
  for (int i = 0; i < 3; ++i) plate_triangle[0].x[i] = obstacle.nodes[i].x;
  EXPECT_GE(probe.separation(plate_triangle, {}), 1e-4);
}

TEST(WorldGuard, AllowsEditsThatComeNoCloserThanBefore) {
  const Mesh sheet = testing::make_grid(2, 2, 1.0, 1.0, testing::Diagonal::kForward, 10, 10);  // far away
  const Mesh obstacle = remesh_test::mesh_from({Vec3(0, 0, 1e-5), Vec3(1, 0, 1e-5), Vec3(0, 1, 1e-5)}, {{0, 1, 2}});
  const WorldGuard guard(sheet, {&obstacle}, 1e-4);
  GuardTriangle low, lower, high;
  low.x = {Vec3(0.2, 0.2, 0), Vec3(0.4, 0.2, 0), Vec3(0.2, 0.4, 0)};
  lower = low;
  for (Vec3& p : lower.x) p.z() = 5e-6;
  high = low;
  for (Vec3& p : high.x) p.z() = -1e-3;
  EXPECT_NEAR(guard.separation({low}, {}), 1e-5, 1e-15);
  EXPECT_TRUE(guard.allows({low}, {high}, {}, {}));   // moves away beyond the clearance
  EXPECT_TRUE(guard.allows({low}, {low}, {}, {}));    // already closer than the clearance, no closer
  EXPECT_FALSE(guard.allows({low}, {lower}, {}, {})); // closer still
  // Moving through the obstacle to the far side is refused although the end is clear.
  GuardTriangle through = low;
  for (Vec3& p : through.x) p.z() = 1e-3;
  GuardSweep sweep{{low.x[0], through.x[0], low.x[1], low.x[2]}, {}};
  EXPECT_FALSE(guard.allows({low}, {through}, {sweep}, {}));
  EXPECT_TRUE(guard.allows({low}, {high}, {GuardSweep{{low.x[0], high.x[0], low.x[1], low.x[2]}, {}}}, {}));
}

// allows_move answers from one walk of the grid what its queries answer each from their own: random moves of
// nodes of a bumpy sheet over a second bumpy sheet (an obstacle), some through it, some folding a fan.
TEST(WorldGuard, AllowsMoveAnswersAsItsSeparateQueries) {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> sym(-1, 1);
  Mesh sheet = testing::make_grid(10, 10, 1.0, 1.0, testing::Diagonal::kAlternating);
  Mesh obstacle = testing::make_grid(6, 6, 1.2, 1.2, testing::Diagonal::kForward, -0.1, -0.1);
  for (Node& n : sheet.nodes) n.x.z() = n.x0.z() = 0.03 * std::sin(11 * n.x.x()) * std::cos(9 * n.x.y());
  for (Node& n : obstacle.nodes) n.x.z() = n.x0.z() = -0.04 + 0.02 * sym(rng);
  const WorldGuard guard(sheet, {&obstacle}, 0.01);
  int kept = 0, refused = 0, folded = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const int node = static_cast<int>(rng() % sheet.nodes.size());
    const Vec3 from = sheet.nodes[node].x;
    const double reach = trial % 3 == 0 ? 0.25 : 0.03;
    const std::vector<GuardTriangle> before = guard.fan(node);
    sheet.nodes[node].x += reach * Vec3(sym(rng), sym(rng), sym(rng));
    const std::vector<GuardTriangle> after = guard.fan(node);
    const std::vector<GuardSweep> sweeps = guard.fan_sweep(node, from);
    const std::vector<int> fan_faces = sheet.node_faces(node);  // ascending
    std::vector<int> replaced;
    if (trial % 2 == 1) replaced.push_back(fan_faces[rng() % fan_faces.size()]);
    std::vector<int> sorted = replaced;
    std::sort(sorted.begin(), sorted.end());
    const bool folds = guard.folds_through_neighbours(after, fan_faces);
    const double gap_after = guard.separation(after, sorted);
    const bool separately = !folds && guard.sweep_is_clear(sweeps, sorted) &&
                            (gap_after >= guard.clearance() || gap_after >= guard.separation(before, sorted));
    ASSERT_EQ(guard.allows_move(before, after, sweeps, &fan_faces, replaced), separately) << "trial " << trial;
    ASSERT_EQ(guard.allows_move(before, after, sweeps, nullptr, replaced), guard.allows(before, after, sweeps, replaced))
        << "trial " << trial;
    (separately ? kept : refused) += 1;
    folded += folds;
    sheet.nodes[node].x = from;
  }
  // Both answers, and refusals by the fold test, occurred.
  EXPECT_GT(kept, 50);
  EXPECT_GT(refused, 50);
  EXPECT_GT(folded, 5);
}

// An edit that splits a node (a crack opening) may not leave two of its own faces crossing: faces that shared
// the node before and share none after must not meet after, unless they already crossed before.
TEST(EditMakesCrossing, FacesThatASplitSeparatesMustNotMeet) {
  const GuardTriangle a{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {0, 1, 2}};
  // b shares node 0 with a; its other corners lie either side of a's plane, over a's interior.
  const GuardTriangle b{{Vec3(0, 0, 0), Vec3(0.2, 0.2, 0.5), Vec3(-1, -1, 0)}, {0, 3, 4}};
  GuardTriangle b_moved = b;  // node 0 split: b's copy (a new id) moved under a, its edge to node 3 piercing a
  b_moved.x[0] = Vec3(0.2, 0.2, -0.5);
  b_moved.nodes[0] = -2;
  ASSERT_TRUE(triangles_intersect(a.x, b_moved.x));
  EXPECT_TRUE(edit_makes_crossing({a, b}, {a, b_moved}));
  // The same positions with node 0 still shared: neighbours are not compared (they meet at their node).
  GuardTriangle b_same_node = b_moved;
  b_same_node.nodes[0] = 0;
  EXPECT_FALSE(edit_makes_crossing({a, b}, {a, b_same_node}));
  // Crossing already before, sharing no node then: not the edit's doing.
  GuardTriangle b_apart = b_moved;
  b_apart.nodes[0] = 5;
  EXPECT_FALSE(edit_makes_crossing({a, b_apart}, {a, b_moved}));
  // The copy moved away from a instead: nothing meets.
  GuardTriangle b_away = b_moved;
  b_away.x[0] = Vec3(-0.2, -0.2, 0);
  EXPECT_FALSE(edit_makes_crossing({a, b}, {a, b_away}));
  // kNone corners (not in the mesh) never count as shared.
  GuardTriangle a_unknown = a, b_unknown = b_moved;
  a_unknown.nodes = {kNone, kNone, kNone};
  b_unknown.nodes = {kNone, kNone, kNone};
  EXPECT_TRUE(edit_makes_crossing({a, b}, {a_unknown, b_unknown}));
}

// before and after are the same faces, index for index: lists of different sizes are a caller's mistake, not
// an edit to judge on the faces they have in common.
TEST(EditMakesCrossing, ThrowsIfBeforeAndAfterDifferInSize) {
  const GuardTriangle a{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {0, 1, 2}};
  const GuardTriangle b{{Vec3(0, 0, 0), Vec3(0.2, 0.2, 0.5), Vec3(-1, -1, 0)}, {0, 3, 4}};
  EXPECT_THROW(edit_makes_crossing({a, b}, {a}), std::invalid_argument);
  EXPECT_THROW(edit_makes_crossing({a}, {a, b}), std::invalid_argument);
  EXPECT_THROW(edit_makes_crossing({}, {a}), std::invalid_argument);
  EXPECT_NO_THROW(edit_makes_crossing({}, {}));
}

}  // namespace
}  // namespace arcsim
