// collision/intersections.hpp: the hierarchy-driven search finds exactly the pairs a brute-force loop over all
// face pairs finds (within a sheet, between sheets, against obstacles), skips adjacent faces, and ignores dead
// faces.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <tuple>

#include "collision/intersections.hpp"
#include "collision/triangle_intersection.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using Key = std::tuple<int, int, bool, int, int>;

std::array<Vec3, 3> triangle(const Mesh& m, int f) {
  return {m.nodes[m.face_node(f, 0)].x, m.nodes[m.face_node(f, 1)].x, m.nodes[m.face_node(f, 2)].x};
}

bool adjacent(const Mesh& m, int f, int g) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (m.face_node(f, i) == m.face_node(g, j)) return true;
  return false;
}

std::set<Key> brute_force(const std::vector<const Mesh*>& sheets, const std::vector<const Mesh*>& obstacles) {
  std::set<Key> out;
  auto live = [](const Mesh& m, int f) { return !m.faces[f].dead; };
  for (int a = 0; a < static_cast<int>(sheets.size()); ++a) {
    const Mesh& A = *sheets[a];
    for (int f = 0; f < static_cast<int>(A.faces.size()); ++f) {
      if (!live(A, f)) continue;
      for (int g = f + 1; g < static_cast<int>(A.faces.size()); ++g)
        if (live(A, g) && !adjacent(A, f, g) && triangles_intersect(triangle(A, f), triangle(A, g)))
          out.insert({a, f, false, a, g});
      for (int b = a + 1; b < static_cast<int>(sheets.size()); ++b)
        for (int g = 0; g < static_cast<int>(sheets[b]->faces.size()); ++g)
          if (live(*sheets[b], g) && triangles_intersect(triangle(A, f), triangle(*sheets[b], g)))
            out.insert({a, f, false, b, g});
      for (int b = 0; b < static_cast<int>(obstacles.size()); ++b)
        for (int g = 0; g < static_cast<int>(obstacles[b]->faces.size()); ++g)
          if (live(*obstacles[b], g) && triangles_intersect(triangle(A, f), triangle(*obstacles[b], g)))
            out.insert({a, f, true, b, g});
    }
  }
  return out;
}

// A grid whose nodes are scattered at random in a box: a crumpled sheet that crosses itself many times.
Mesh scrambled_grid(std::mt19937& rng, int cells, double spread, const Vec3& offset) {
  Mesh m = testing::make_grid(cells, cells, 1, 1, testing::Diagonal::kAlternating);
  std::uniform_real_distribution<double> jitter(-spread, spread);
  for (Node& n : m.nodes) n.x += offset + Vec3(jitter(rng), jitter(rng), jitter(rng));
  return m;
}

TEST(Intersections, MatchesBruteForceWithinAndBetweenSheetsAndObstacles) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    Mesh a = scrambled_grid(rng, 8, 0.15, Vec3::Zero());
    Mesh b = scrambled_grid(rng, 6, 0.1, Vec3(0.3, 0.2, 0));
    Mesh floor = testing::make_grid(2, 2, 2, 2, testing::Diagonal::kForward, -0.5, -0.5);
    for (Node& n : floor.nodes) n.x.z() = -0.05;
    if (trial % 2) a.faces[3].dead = true;  // dead faces take no part
    const std::vector<const Mesh*> sheets{&a, &b}, obstacles{&floor};
    const std::set<Key> expected = brute_force(sheets, obstacles);
    std::set<Key> found;
    for (const IntersectingPair& p : intersecting_pairs(sheets, obstacles)) {
      EXPECT_TRUE(found.insert({p.sheet_a, p.face_a, p.obstacle, p.sheet_b, p.face_b}).second) << "reported twice";
      if (trial % 2) {
        EXPECT_FALSE(p.sheet_a == 0 && p.face_a == 3) << "a dead face";
      }
    }
    EXPECT_EQ(found, expected) << "trial " << trial;
    // The random sheets do cross themselves, each other and the floor: the comparison is not vacuous.
    int self = 0, between = 0, with_floor = 0;
    for (const Key& k : expected) {
      if (std::get<2>(k)) ++with_floor;
      else if (std::get<0>(k) == std::get<3>(k)) ++self;
      else ++between;
    }
    EXPECT_GT(self, 0);
    EXPECT_GT(between, 0);
    EXPECT_GT(with_floor, 0);
  }
}

TEST(Intersections, AFlatSheetAndItsAdjacentFacesAreClean) {
  Mesh a = testing::make_grid(5, 5, 1, 1, testing::Diagonal::kAlternating);
  EXPECT_TRUE(intersecting_pairs({&a}, {}).empty());
  // A second sheet 1 mm above: clean; moved into the plane of the first: every overlapping pair is found.
  Mesh b = testing::make_grid(3, 3, 0.3, 0.3, testing::Diagonal::kForward, 0.2, 0.2);
  for (Node& n : b.nodes) n.x.z() = 1e-3;
  EXPECT_TRUE(intersecting_pairs({&a, &b}, {}).empty());
  for (Node& n : b.nodes) n.x.z() = 0;
  EXPECT_EQ(intersecting_pairs({&a, &b}, {}).size(), brute_force({&a, &b}, {}).size());
  EXPECT_FALSE(intersecting_pairs({&a, &b}, {}).empty());
}

}  // namespace
}  // namespace arcsim
