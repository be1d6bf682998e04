// Broad phase: BVH overlaps against all-pairs box tests, refitting, determinism across thread counts, and the
// primitive candidates of whole meshes against brute force over every primitive pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "collision/bvh.hpp"
#include "collision/candidates.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

std::vector<Aabb> random_boxes(int n, unsigned seed, double size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Aabb> boxes(n);
  for (auto& b : boxes) {
    const Vec3 c(U(rng), U(rng), U(rng));
    b.extend(c);
    b.extend(c + size * Vec3(U(rng), U(rng), U(rng)));
  }
  return boxes;
}

std::vector<std::pair<int, int>> sorted(std::vector<std::pair<int, int>> pairs) {
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

std::vector<std::pair<int, int>> brute_self(const std::vector<Aabb>& boxes) {
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j])) pairs.emplace_back(i, j);
  return pairs;
}

TEST(Bvh, SelfOverlapsMatchAllPairs) {
  for (int n : {1, 2, 3, 17, 400}) {
    const auto boxes = random_boxes(n, 1 + n, 0.08);
    Bvh bvh;
    bvh.build(boxes);
    EXPECT_EQ(sorted(bvh.self_overlaps()), brute_self(boxes)) << n << " boxes";
  }
}

TEST(Bvh, CrossOverlapsMatchAllPairs) {
  const auto a = random_boxes(300, 5, 0.1), b = random_boxes(200, 6, 0.1);
  Bvh ta, tb;
  ta.build(a);
  tb.build(b);
  std::vector<std::pair<int, int>> expected;
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j)
      if (a[i].overlaps(b[j])) expected.emplace_back(i, j);
  EXPECT_EQ(sorted(ta.overlaps(tb)), expected);
  EXPECT_FALSE(expected.empty());
}

TEST(Bvh, RefitFollowsMovedBoxes) {
  auto boxes = random_boxes(300, 9, 0.05);
  Bvh bvh;
  bvh.build(boxes);
  // Move every box far and differently: the tree structure is now poor but must stay correct.
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> U(-1, 1);
  for (auto& b : boxes) {
    const Vec3 shift(U(rng), U(rng), U(rng));
    b.lo += shift;
    b.hi += shift;
  }
  bvh.refit(boxes);
  EXPECT_EQ(sorted(bvh.self_overlaps()), brute_self(boxes));
}

TEST(Bvh, PairsAndTheirOrderDoNotDependOnThreadCount) {
#ifdef _OPENMP
  // 3000 boxes: 5999 tree nodes, counted twice in a self traversal, above bvh.cpp's kParallelNodes (8192), so
  // that with several threads the traversal is split into items shared among them.
  const auto boxes = random_boxes(3000, 12, 0.05), other = random_boxes(2500, 13, 0.05);
  Bvh bvh, tree;
  bvh.build(boxes);
  tree.build(other);
  ASSERT_GE(2 * (2 * boxes.size() - 1), 8192u);
  ASSERT_GE(2 * boxes.size() - 1 + 2 * other.size() - 1, 8192u);
  const int saved = omp_get_max_threads();
  const int saved_dynamic = omp_get_dynamic();
  omp_set_dynamic(0);
  omp_set_num_threads(1);
  const auto self_one = bvh.self_overlaps();
  const auto cross_one = bvh.overlaps(tree);
  for (int threads : {2, 3, 4}) {
    omp_set_num_threads(threads);
    // The same pairs in the same order, unsorted: callers may consume them in order.
    EXPECT_EQ(bvh.self_overlaps(), self_one) << threads << " threads";
    EXPECT_EQ(bvh.overlaps(tree), cross_one) << threads << " threads";
  }
  omp_set_num_threads(saved);
  omp_set_dynamic(saved_dynamic);
  EXPECT_GT(self_one.size(), 300u);
  EXPECT_GT(cross_one.size(), 300u);
  // And they are the right pairs.
  EXPECT_EQ(sorted(self_one), brute_self(boxes));
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

TEST(Bvh, DirtyFlagsKeepOnlyPairsWithADirtyPrimitive) {
  const auto a = random_boxes(300, 21, 0.1), b = random_boxes(200, 22, 0.1);
  Bvh ta, tb;
  ta.build(a);
  tb.build(b);
  std::vector<char> dirty_a(a.size(), 0), dirty_b(b.size(), 0);
  for (size_t i = 0; i < a.size(); i += 7) dirty_a[i] = 1;
  for (size_t i = 0; i < b.size(); i += 11) dirty_b[i] = 1;
  std::vector<std::pair<int, int>> expected_self, expected_cross;
  for (const auto& p : brute_self(a))
    if (dirty_a[p.first] || dirty_a[p.second]) expected_self.push_back(p);
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j)
      if (a[i].overlaps(b[j]) && (dirty_a[i] || dirty_b[j])) expected_cross.emplace_back(i, j);
  EXPECT_EQ(sorted(ta.self_overlaps(&dirty_a)), expected_self);
  EXPECT_EQ(sorted(ta.overlaps(tb, &dirty_a, &dirty_b)), expected_cross);
  EXPECT_FALSE(expected_self.empty());
  // Only one side flagged: the other counts as clean.
  std::vector<std::pair<int, int>> only_a;
  for (const auto& p : expected_cross)
    if (dirty_a[p.first]) only_a.push_back(p);
  EXPECT_EQ(sorted(ta.overlaps(tb, &dirty_a, nullptr)), only_a);
}

// Brute force over every primitive pair of the geometry, with the same box and adjacency rules.
std::vector<PrimitivePair> brute_candidates(const ContactGeometry& g, double margin, bool swept) {
  auto node_box = [&](int n) {
    Aabb b;
    b.extend(g.x0[n]);
    if (swept) b.extend(g.x1[n]);
    b.inflate(0.5 * margin);
    return b;
  };
  auto both_static = [&](int mesh_a, int mesh_b) {
    return !g.meshes[mesh_a].deformable && !g.meshes[mesh_b].deformable;
  };
  std::vector<PrimitivePair> out;
  for (int n = 0; n < g.node_count(); ++n) {
    for (size_t f = 0; f < g.faces.size(); ++f) {
      const auto& v = g.faces[f];
      if (v[0] == n || v[1] == n || v[2] == n || both_static(g.node_mesh[n], g.node_mesh[v[0]])) continue;
      Aabb fb;
      for (int k : v) fb.extend(node_box(k));
      if (node_box(n).overlaps(fb)) out.push_back({PairKind::kVertexFace, n, static_cast<int>(f)});
    }
  }
  for (size_t a = 0; a < g.edges.size(); ++a) {
    for (size_t b = a + 1; b < g.edges.size(); ++b) {
      const auto &ea = g.edges[a], &eb = g.edges[b];
      if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) continue;
      if (both_static(g.node_mesh[ea[0]], g.node_mesh[eb[0]])) continue;
      Aabb ba = node_box(ea[0]), bb = node_box(eb[0]);
      ba.extend(node_box(ea[1]));
      bb.extend(node_box(eb[1]));
      if (ba.overlaps(bb)) out.push_back({PairKind::kEdgeEdge, static_cast<int>(a), static_cast<int>(b)});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// A crumpled sheet (random heights) above a static plate, moving down through it.
struct TwoMeshes {
  Mesh sheet, plate;
  ContactGeometry g;
  explicit TwoMeshes(unsigned seed, int cells = 8) {
    sheet = testing::make_grid(cells, cells, 1, 1, testing::Diagonal::kAlternating);
    plate = testing::make_grid(3, 3, 1.2, 1.2, testing::Diagonal::kForward, -0.1, -0.1);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(-1, 1);
    for (Node& n : sheet.nodes) {
      n.x0 = n.x + Vec3(0, 0, 0.05 + 0.04 * U(rng));
      n.x = n.x0 + Vec3(0.02 * U(rng), 0.02 * U(rng), -0.1);
      n.mass = 0.01;
    }
    for (Node& n : plate.nodes) n.x0 = n.x;
    build_contact_geometry({{&sheet, true}, {&plate, false}}, ContactStage::kAfterStep, 0.01, g);
  }
};

// find_candidates on fresh trees against brute force, with swept and static boxes; returns the counts found.
std::vector<size_t> expect_candidates_match_brute_force(const TwoMeshes& m, double margin, const std::string& what) {
  std::vector<size_t> counts;
  for (bool swept : {true, false}) {
    BvhCache cache;
    CandidateOptions options;
    options.margin = margin;
    options.swept = swept;
    const auto found = find_candidates(m.g, cache, options);
    const auto expected = brute_candidates(m.g, options.margin, swept);
    EXPECT_EQ(found.size(), expected.size()) << what << " swept " << swept;
    EXPECT_TRUE(found == expected) << what << " swept " << swept;
    counts.push_back(found.size());
  }
  return counts;
}

TEST(Candidates, MatchBruteForceForSweptAndStaticBoxes) {
  for (unsigned seed : {1u, 2u})
    for (size_t count : expect_candidates_match_brute_force(TwoMeshes(seed), 0.01, "seed " + std::to_string(seed)))
      EXPECT_GT(count, 0u);
}

// Thousands of candidates: the search sorts them by counting (collision/candidates.cpp, sort_unique), not by
// std::sort, which the small sheet above keeps to.
TEST(Candidates, MatchBruteForceWithThousandsOfCandidates) {
  for (size_t count : expect_candidates_match_brute_force(TwoMeshes(5, 20), 0.08, "20x20 sheet"))
    EXPECT_GE(count, 4096u);
}

TEST(Candidates, MovedFlagsKeepOnlyPairsTouchingMovedNodes) {
  TwoMeshes m(4);
  std::vector<char> moved(m.g.node_count(), 0);
  for (int n = 0; n < m.g.node_count(); n += 5) moved[n] = 1;
  BvhCache cache;
  CandidateOptions options;
  options.margin = 0.01;
  options.swept = true;
  std::vector<PrimitivePair> expected;
  for (const PrimitivePair& p : find_candidates(m.g, cache, options)) {
    const auto nodes = pair_nodes(m.g, p);
    bool touches = false;
    for (int n : nodes) touches = touches || (n != kNone && moved[n]);
    if (touches) expected.push_back(p);
  }
  options.moved = &moved;
  EXPECT_TRUE(find_candidates(m.g, cache, options) == expected);
  EXPECT_FALSE(expected.empty());
}

TEST(Candidates, BvhIsRebuiltOnlyWhenTopologyChanges) {
  TwoMeshes m(3);
  BvhCache cache;
  CandidateOptions options;
  options.margin = 0.01;
  find_candidates(m.g, cache, options);
  EXPECT_EQ(cache.builds(), 2);
  // Same topology, new positions: refit only.
  for (Vec3& x : m.g.x1) x.z() -= 0.01;
  find_candidates(m.g, cache, options);
  EXPECT_EQ(cache.builds(), 2);
  // New sheet topology: that mesh's tree is rebuilt.
  m.sheet = testing::make_grid(5, 5, 1, 1);
  for (Node& n : m.sheet.nodes) n.mass = 0.01;
  build_contact_geometry({{&m.sheet, true}, {&m.plate, false}}, ContactStage::kAfterStep, 0.01, m.g);
  find_candidates(m.g, cache, options);
  EXPECT_EQ(cache.builds(), 3);
}

// Moves every sheet node of the geometry (both ends of its step) by up to `step` per axis.
void jiggle(ContactGeometry& g, std::mt19937& rng, double step) {
  std::uniform_real_distribution<double> U(-step, step);
  for (int n = 0; n < g.node_count(); ++n) {
    if (!g.movable(n)) continue;
    const Vec3 d(U(rng), U(rng), U(rng));
    g.x0[n] += d;
    g.x1[n] += d;
  }
}

TEST(Candidates, AKeptListFindsWhatAFreshSearchFinds) {
  // Small moves stay within the list's slack (the list is reused), large ones leave it (a new list is made):
  // either way the kept cache finds exactly what a fresh cache and brute force find.
  for (bool swept : {true, false}) {
    TwoMeshes m(5);
    std::mt19937 rng(7);
    BvhCache kept;
    CandidateOptions options;
    options.margin = 0.01;
    options.swept = swept;
    options.vertex_edge = !swept;
    find_candidates(m.g, kept, options);
    EXPECT_EQ(kept.list_builds(), 1);
    for (int round = 0; round < 12; ++round) {
      jiggle(m.g, rng, round % 4 == 3 ? 0.05 : 0.002);
      BvhCache fresh;
      const auto found = find_candidates(m.g, kept, options);
      EXPECT_TRUE(found == find_candidates(m.g, fresh, options)) << "round " << round << " swept " << swept;
      if (!swept) continue;  // brute_candidates has no vertex-edge pairs
      EXPECT_TRUE(found == brute_candidates(m.g, options.margin, swept)) << "round " << round;
    }
    EXPECT_GT(kept.list_builds(), 1);   // the large moves left the slack
    EXPECT_LT(kept.list_builds(), 12);  // the small ones did not
  }
}

TEST(Candidates, AKeptListServesSearchesWithMovedFlags) {
  TwoMeshes m(6);
  std::mt19937 rng(8);
  BvhCache kept;
  CandidateOptions options;
  options.margin = 0.01;
  options.swept = true;
  find_candidates(m.g, kept, options);
  std::vector<char> moved(m.g.node_count(), 0);
  for (int n = 0; n < m.g.node_count(); n += 3) moved[n] = 1;
  options.moved = &moved;
  for (double step : {0.001, 0.05}) {  // within the slack, then beyond it
    jiggle(m.g, rng, step);
    BvhCache fresh;
    EXPECT_TRUE(find_candidates(m.g, kept, options) == find_candidates(m.g, fresh, options)) << step;
  }
}

TEST(Candidates, AKeptListIsDroppedWhenTheTopologyChanges) {
  TwoMeshes m(3);
  BvhCache kept;
  CandidateOptions options;
  options.margin = 0.01;
  find_candidates(m.g, kept, options);
  find_candidates(m.g, kept, options);  // served twice: it paid, so the next search that cannot use it makes one
  EXPECT_EQ(kept.list_builds(), 1);
  // Same positions, new sheet connectivity (flipped diagonals): the list no longer fits.
  m.sheet = testing::make_grid(8, 8, 1, 1, testing::Diagonal::kForward);
  for (Node& n : m.sheet.nodes) n.mass = 0.01;
  build_contact_geometry({{&m.sheet, true}, {&m.plate, false}}, ContactStage::kAfterStep, 0.01, m.g);
  BvhCache fresh;
  EXPECT_TRUE(find_candidates(m.g, kept, options) == find_candidates(m.g, fresh, options));
  EXPECT_EQ(kept.list_builds(), 2);
}

}  // namespace
}  // namespace arcsim
