// Randomised sequences of mixed edits (split, flip, collapse, node split) on flat, curved and seamed meshes,
// with check_mesh() after every edit, compaction every so often, and bounds on every piece of inherited state.
// Deterministic: fixed seeds.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "mesh/edits.hpp"
#include "mesh/validate.hpp"
#include "mesh_fixtures.hpp"

namespace arcsim {
namespace {

using test::fingerprint;
using test::live_count;

enum class Shape { kFlat, kCylinder, kSeamedTube };

struct Counts {
  int split = 0, flip = 0, collapse = 0, node_split = 0, refused = 0;
};

// Bounds that inherited state can never leave: every edit copies, interpolates or averages it.
struct Bounds {
  Vec3 x_lo, x_hi;
};

Bounds world_bounds(const Mesh& m) {
  Bounds b{Vec3::Constant(kInfinity), Vec3::Constant(-kInfinity)};
  for (const Node& n : m.nodes) {
    b.x_lo = b.x_lo.cwiseMin(n.x);
    b.x_hi = b.x_hi.cwiseMax(n.x);
  }
  return b;
}

// Returns "" or the first state value out of its bounds.
std::string check_state_bounds(const Mesh& m, const Bounds& b, Shape shape) {
  const double eps = 1e-12;
  for (size_t i = 0; i < m.faces.size(); ++i) {
    const Face& f = m.faces[i];
    if (f.dead) continue;
    std::ostringstream where;
    where << "face " << i << ": ";
    if (!(f.thickness >= 1e-3 - eps && f.thickness <= 2e-3 + eps)) return where.str() + "thickness";
    if (!(f.damage >= -eps && f.damage <= 1 + eps)) return where.str() + "damage";
    if (!((f.Fp - Mat3::Identity()).cwiseAbs().maxCoeff() <= 0.1 + eps)) return where.str() + "Fp";
    if (!(f.Sp.cwiseAbs().maxCoeff() <= 1 + eps)) return where.str() + "Sp";
    if (!(f.material == 0 || f.material == 1)) return where.str() + "material";
    // No face is ever inverted: planar rest shapes keep +z normals (see also check_new_faces_follow_old).
    if (shape != Shape::kCylinder && !(f.rest_normal.z() > 0)) return where.str() + "inverted in the rest plane";
  }
  for (size_t i = 0; i < m.edges.size(); ++i) {
    const Edge& e = m.edges[i];
    if (e.dead) continue;
    if (!(e.damage >= -eps && e.damage <= 1 + eps)) return "edge " + std::to_string(i) + ": damage";
    // The plastic offset (rest_theta minus rest dihedral) starts in [-0.1, 0.1] and edits carry it over; on
    // planar rest shapes every rest dihedral is 0, so the bound holds for rest_theta itself. (Crack lips keep
    // the angle they had as interior edges, so on curved shapes boundary edges are exempt.)
    const double offset = e.rest_theta - m.rest_dihedral(static_cast<int>(i));
    if (shape != Shape::kCylinder && !(std::abs(e.rest_theta) <= 0.1 + eps))
      return "edge " + std::to_string(i) + ": rest_theta";
    if (!e.is_boundary() && !(std::abs(offset) <= 0.1 + 1e-9))
      return "edge " + std::to_string(i) + ": plastic offset of rest_theta";
  }
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const Node& n = m.nodes[i];
    if (n.dead) continue;
    if (!((n.x - b.x_lo).minCoeff() >= -eps && (b.x_hi - n.x).minCoeff() >= -eps))
      return "node " + std::to_string(i) + ": x outside the initial bounding box";
    if (!(n.v.cwiseAbs().maxCoeff() <= 1 + eps && n.a.cwiseAbs().maxCoeff() <= 1 + eps))
      return "node " + std::to_string(i) + ": v or a";
  }
  return "";
}

// Every element an edit reports as added is alive, every one reported removed is dead.
std::string check_result_lists(const Mesh& m, const EditResult& r) {
  for (int i : r.added_nodes)
    if (m.nodes.at(i).dead) return "added node dead";
  for (int i : r.added_verts)
    if (m.verts.at(i).dead) return "added vert dead";
  for (int i : r.added_edges)
    if (m.edges.at(i).dead) return "added edge dead";
  for (int i : r.added_faces)
    if (m.faces.at(i).dead) return "added face dead";
  for (int i : r.removed_nodes)
    if (!m.nodes.at(i).dead) return "removed node alive";
  for (int i : r.removed_verts)
    if (!m.verts.at(i).dead) return "removed vert alive";
  for (int i : r.removed_edges)
    if (!m.edges.at(i).dead) return "removed edge alive";
  for (int i : r.removed_faces)
    if (!m.faces.at(i).dead) return "removed face alive";
  return "";
}

// Each new face turns its rest normal by at most 60 degrees from a face it replaced (removed faces keep their
// data as tombstones). On a curved sheet this is the local form of "never inverted".
std::string check_new_faces_follow_old(const Mesh& m, const EditResult& r) {
  if (r.removed_faces.empty()) return "";
  for (int a : r.added_faces) {
    double best = -1;
    for (int f : r.removed_faces) best = std::max(best, m.faces[a].rest_normal.dot(m.faces[f].rest_normal));
    if (!(best >= 0.5 - 1e-9)) return "face " + std::to_string(a) + " turned away from the faces it replaced";
  }
  return "";
}

bool empty_result(const EditResult& r) {
  return r.added_nodes.empty() && r.added_verts.empty() && r.added_edges.empty() && r.added_faces.empty() &&
         r.removed_nodes.empty() && r.removed_verts.empty() && r.removed_edges.empty() && r.removed_faces.empty();
}

template <typename T>
int random_live(const std::vector<T>& items, std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, static_cast<int>(items.size()) - 1);
  for (int tries = 0; tries < 1000; ++tries) {
    const int i = pick(rng);
    if (!items[i].dead) return i;
  }
  return kNone;
}

// Interior edges at `node` (candidate crack directions).
std::vector<int> interior_edges_at(const Mesh& m, int node) {
  std::vector<int> result;
  for (int e : m.nodes[node].edges)
    if (!m.edges[e].is_boundary()) result.push_back(e);
  return result;
}

Mesh make_shape(Shape shape) {
  switch (shape) {
    case Shape::kFlat: return test::make_flat_grid(8, 6, 1.0, 0.75);
    case Shape::kCylinder: return test::make_cylinder_patch(8, 6, 1.0, 1.5, 1.0);
    case Shape::kSeamedTube: return test::make_seamed_tube(8, 5, 0.2, 1.0);
  }
  return Mesh();
}

// Prepares state: random values, a few preserved edges, a second material on part of the sheet.
void decorate(Mesh& m, std::mt19937& rng) {
  test::fill_random_state(m, rng);
  std::uniform_real_distribution<double> unit(0, 1);
  for (Edge& e : m.edges) e.preserve = unit(rng) < 0.04;
  for (size_t f = 0; f < m.faces.size(); ++f)
    if (f % 7 == 0) m.faces[f].material = 1;
}

// Runs `steps` random edits; fails the test at the first inconsistency.
Counts run_random_edits(Shape shape, unsigned seed, int steps, double fracture_rate) {
  std::mt19937 rng(seed);
  Mesh m = make_shape(shape);
  decorate(m, rng);
  const Bounds bounds = world_bounds(m);
  EXPECT_EQ(check_mesh(m), "");
  Counts counts;
  std::uniform_real_distribution<double> unit(0, 1);
  const int face_cap = 200, face_floor = 40;
  double area = test::total_rest_area(m);
  for (int step = 0; step < steps; ++step) {
    const uint64_t before = fingerprint(m);
    const int faces = live_count(m.faces);
    const double dice = unit(rng);
    EditResult r;
    std::string op;
    bool area_may_change = false;
    if (dice < fracture_rate) {
      const int node = random_live(m.nodes, rng);
      if (node == kNone) continue;
      std::vector<int> cuts = interior_edges_at(m, node);
      std::shuffle(cuts.begin(), cuts.end(), rng);
      const bool interior = !m.is_boundary_node(node);
      const size_t wanted = interior ? 2 : (cuts.size() >= 2 && unit(rng) < 0.3 ? 2 : 1);
      if (cuts.size() < wanted) continue;
      cuts.resize(wanted);
      op = "split_node";
      r = split_node(m, node, cuts);
      // Every well-formed request on a valid mesh must succeed.
      if (!r.ok) {
        ADD_FAILURE() << "split_node refused a valid request at step " << step << " (seed " << seed << ")";
        return counts;
      }
      ++counts.node_split;
    } else if (dice < fracture_rate + 0.3 && faces < face_cap) {
      op = "split_edge";
      r = split_edge(m, random_live(m.edges, rng), 0.1 + 0.8 * unit(rng));
      counts.split += r.ok;
    } else if (dice < fracture_rate + 0.6) {
      op = "flip_edge";
      r = flip_edge(m, random_live(m.edges, rng));
      counts.flip += r.ok;
    } else if (faces > face_floor) {
      op = "collapse_edge";
      const int e = random_live(m.edges, rng);
      if (e == kNone) continue;
      const int side = unit(rng) < 0.5 ? 0 : 1;
      area_may_change = m.is_boundary_node(m.edges[e].n[side]);
      r = collapse_edge(m, e, side);
      counts.collapse += r.ok;
    } else {
      continue;
    }
    std::ostringstream where;
    where << op << " at step " << step << " (seed " << seed << ")";
    if (!r.ok) {
      ++counts.refused;
      if (fingerprint(m) != before || !empty_result(r)) {
        ADD_FAILURE() << "refused " << where.str() << " changed the mesh or reported changes";
        return counts;
      }
      continue;
    }
    const std::string problem = check_mesh(m);
    if (!problem.empty()) {
      ADD_FAILURE() << where.str() << ": " << problem;
      return counts;
    }
    const std::string lists = check_result_lists(m, r) + check_new_faces_follow_old(m, r);
    const std::string state = check_state_bounds(m, bounds, shape);
    if (!lists.empty() || !state.empty()) {
      ADD_FAILURE() << where.str() << ": " << lists << state;
      return counts;
    }
    // Planar rest shapes: only moving the boundary (a boundary collapse) may change the total rest area.
    const double new_area = test::total_rest_area(m);
    if (shape != Shape::kCylinder && !area_may_change && std::abs(new_area - area) > 1e-12 * area) {
      ADD_FAILURE() << where.str() << ": rest area changed from " << area << " to " << new_area;
      return counts;
    }
    area = new_area;
    if (step % 97 == 96) {
      const int live_faces = live_count(m.faces);
      m.compact();
      EXPECT_TRUE(m.is_compact());
      EXPECT_EQ(static_cast<int>(m.faces.size()), live_faces);
      const std::string after = check_mesh(m);
      if (!after.empty()) {
        ADD_FAILURE() << "compact after step " << step << ": " << after;
        return counts;
      }
    }
  }
  m.compact();
  EXPECT_EQ(check_mesh(m), "");
  return counts;
}

// Each run checks at least `minimum` successful edits of every kind (and some refusals).
void run_and_expect(Shape shape, unsigned seed, int steps, double fracture_rate) {
  const Counts c = run_random_edits(shape, seed, steps, fracture_rate);
  const int minimum = steps / 25;
  EXPECT_GE(c.split, minimum);
  EXPECT_GE(c.flip, minimum);
  EXPECT_GE(c.collapse, minimum);
  EXPECT_GT(c.refused, 0);
  if (fracture_rate > 0) {
    EXPECT_GE(c.node_split, fracture_rate * steps / 3);
  }
}

TEST(RandomEdits, FlatSheet) { run_and_expect(Shape::kFlat, 1, 1200, 0.0); }
TEST(RandomEdits, FlatSheetWithFracture) { run_and_expect(Shape::kFlat, 3, 1200, 0.02); }
TEST(RandomEdits, CurvedCylinderRestShape) { run_and_expect(Shape::kCylinder, 4, 1200, 0.01); }
TEST(RandomEdits, TubeWithRestSeam) { run_and_expect(Shape::kSeamedTube, 5, 1200, 0.01); }

// Longer runs over more seeds (optimised build only).
TEST(RandomEditsSlow, ManySeedsAllShapes) {
  for (unsigned seed = 100; seed < 103; ++seed) {
    run_and_expect(Shape::kFlat, seed, 4000, 0.01);
    run_and_expect(Shape::kCylinder, seed, 4000, 0.01);
    run_and_expect(Shape::kSeamedTube, seed, 4000, 0.01);
  }
}

// Remeshes a sheet at random (no fracture), then cracks it from the middle of its left border, always moving
// to the neighbour farthest in +x, until the crack reaches another border: the sheet must fall in two pieces.
void crack_across(Shape shape, unsigned seed) {
  std::mt19937 rng(seed);
  Mesh m = make_shape(shape);
  test::fill_random_state(m, rng);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int step = 0; step < 600; ++step) {
    const int e = random_live(m.edges, rng);
    const double dice = unit(rng);
    if (dice < 0.35 && live_count(m.faces) < 300) split_edge(m, e, 0.2 + 0.6 * unit(rng));
    else if (dice < 0.7) flip_edge(m, e);
    else collapse_edge(m, e, unit(rng) < 0.5 ? 0 : 1);
  }
  m.compact();
  ASSERT_EQ(check_mesh(m), "");
  const double area = test::total_rest_area(m);
  // Start: the left-border node closest to mid-height.
  int tip = kNone;
  double best = kInfinity;
  const double mid = shape == Shape::kFlat ? 0.375 : 0.5;
  for (size_t n = 0; n < m.nodes.size(); ++n) {
    const Vec3& x = m.nodes[n].x;
    if (std::abs(x.x()) < 1e-12 && std::abs(x.y() - mid) < best) {
      best = std::abs(x.y() - mid);
      tip = static_cast<int>(n);
    }
  }
  ASSERT_NE(tip, kNone);
  for (int guard = 0;; ++guard) {
    ASSERT_LT(guard, 200);
    int cut = kNone, next = kNone;
    for (int e : interior_edges_at(m, tip)) {
      const int far = m.edges[e].n[0] == tip ? m.edges[e].n[1] : m.edges[e].n[0];
      if (next == kNone || m.nodes[far].x.x() > m.nodes[next].x.x()) cut = e, next = far;
    }
    ASSERT_NE(cut, kNone);
    ASSERT_GT(m.nodes[next].x.x(), m.nodes[tip].x.x());
    const bool reaches_border = m.is_boundary_node(next);
    const EditResult r = split_node(m, tip, {cut});
    ASSERT_TRUE(r.ok);
    ASSERT_EQ(check_mesh(m), "");
    EXPECT_EQ(r.added_nodes.size(), reaches_border ? 2u : 1u);
    if (reaches_border) break;
    tip = next;
  }
  EXPECT_EQ(count_components(m), 2);
  EXPECT_NEAR(test::total_rest_area(m), area, 1e-12 * area);
  m.compact();
  EXPECT_EQ(check_mesh(m), "");
}

TEST(RandomEdits, CrackAcrossRemeshedFlatSheet) {
  for (unsigned seed : {10u, 11u, 12u}) crack_across(Shape::kFlat, seed);
}

TEST(RandomEdits, CrackAcrossRemeshedCylinder) {
  for (unsigned seed : {20u, 21u}) crack_across(Shape::kCylinder, seed);
}

}  // namespace
}  // namespace arcsim
