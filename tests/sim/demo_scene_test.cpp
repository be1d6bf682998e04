// conf/demo.json, the scene `make demo` runs: a notched gel sheet on a table, pulled apart by clamps along two of
// its edges, must tear, and tear the way a notched sheet does: the first crack opens at the notch's tip, the
// crack runs across the sheet near its centre line (not along the clamped edges), and the sheet ends in two
// large pieces. About 20 s optimised, hence the Slow suite (not run under the sanitizers).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/scene_parser.hpp"
#include "mesh/validate.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

Vec3 rest_of(const Mesh& m, int node) { return m.verts[m.nodes[node].verts[0]].u; }

// The sheet's outline in rest space (m), from the mesh before anything tore: its border edges, its bounds and
// its notch's tip (2 cm in from the middle of the left side; meshes/square_notch.obj scaled by 0.2).
struct Outline {
  std::vector<std::pair<Vec3, Vec3>> segments;
  Vec2 low = Vec2::Constant(kInfinity), high = Vec2::Constant(-kInfinity);
  Vec2 tip() const { return Vec2(low.x() + 0.02, 0.5 * (low.y() + high.y())); }
  double centre_y() const { return 0.5 * (low.y() + high.y()); }

  explicit Outline(const Mesh& m) {
    for (const Edge& e : m.edges) {
      if (e.dead || !e.is_boundary()) continue;
      segments.emplace_back(rest_of(m, e.n[0]), rest_of(m, e.n[1]));
    }
    for (const Node& n : m.nodes) {
      if (n.dead) continue;
      const Vec3 u = m.verts[n.verts[0]].u;
      low = low.cwiseMin(u.head<2>());
      high = high.cwiseMax(u.head<2>());
    }
  }

  bool contains(const Vec3& u) const {
    for (const auto& [a, b] : segments) {
      const Vec3 d = b - a;
      const double t = std::clamp((u - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      if ((a + t * d - u).norm() < 1e-9) return true;
    }
    return false;
  }
};

// The rest midpoints of the border edges a crack made (not on the sheet's outline).
std::vector<Vec3> crack_midpoints(const Mesh& m, const Outline& outline) {
  std::vector<Vec3> out;
  for (const Edge& e : m.edges) {
    if (e.dead || !e.is_boundary()) continue;
    const Vec3 a = rest_of(m, e.n[0]), b = rest_of(m, e.n[1]);
    if (outline.contains(a) && outline.contains(b)) continue;
    out.push_back(0.5 * (a + b));
  }
  return out;
}

// Rest areas of the connected pieces, largest first.
std::vector<double> piece_areas(const Mesh& m) {
  std::vector<int> piece(m.faces.size(), -1);
  std::vector<double> areas;
  for (size_t start = 0; start < m.faces.size(); ++start) {
    if (m.faces[start].dead || piece[start] >= 0) continue;
    const int id = static_cast<int>(areas.size());
    areas.push_back(0);
    std::vector<int> stack{static_cast<int>(start)};
    piece[start] = id;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      const Face& face = m.faces[f];
      const Vec3 u0 = m.verts[face.v[0]].u, u1 = m.verts[face.v[1]].u, u2 = m.verts[face.v[2]].u;
      areas[id] += 0.5 * (u1 - u0).cross(u2 - u0).norm();
      for (int e : face.e) {
        for (int g : m.edges[e].f) {
          if (g == kNone || piece[g] >= 0) continue;
          piece[g] = id;
          stack.push_back(g);
        }
      }
    }
  }
  std::sort(areas.rbegin(), areas.rend());
  return areas;
}

fs::path demo_scene() {
  const fs::path meshes = testing::project_meshes();
  if (meshes.empty()) return {};
  const fs::path scene = meshes.parent_path() / "conf" / "demo.json";
  return fs::exists(scene) ? scene : fs::path();
}

TEST(DemoSceneSlow, TheNotchedSheetTearsFromItsNotchStraightAcross) {
  const fs::path scene = demo_scene();
  if (scene.empty()) GTEST_SKIP() << "conf/demo.json not found";
  const fs::path old_dir = fs::current_path();
  fs::current_path(scene.parent_path().parent_path());  // the scene names its files from the repository root
  Simulation sim(load_scene("conf/demo.json"));
  fs::current_path(old_dir);
  ASSERT_TRUE(sim.scene().enabled("fracture"));
  const double sheet_area = piece_areas(sim.cloths[0].mesh).at(0);
  const Outline outline(sim.cloths[0].mesh);
  ASSERT_NEAR(outline.high.y() - outline.low.y(), 0.2, 1e-9);

  int cracks = 0;
  bool first = true;
  while (!sim.finished()) {
    sim.advance_step();
    // fracture_stats sums over the frame so far.
    int frame_cracks = 0;
    for (const FractureStats& f : sim.fracture_stats) frame_cracks += f.cracks;
    const Mesh& m = sim.cloths[0].mesh;
    if (sim.step() % sim.frame_steps() == 0) {
      ASSERT_EQ(check_mesh(m), "") << "step " << sim.step();
      cracks += frame_cracks;
    }
    if (frame_cracks == 0 || !first) continue;
    first = false;
    // The first crack: at the notch's tip, where the stress gathers.
    for (const Vec3& c : crack_midpoints(m, outline))
      EXPECT_LT((c.head<2>() - outline.tip()).norm(), 0.02) << "the first crack opened at " << c.transpose();
  }
  const Mesh& m = sim.cloths[0].mesh;
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_GE(cracks, 10) << "the sheet did not tear";
  // Across the sheet near its centre line: nothing tore along the clamped edges 10 cm away.
  const std::vector<Vec3> crack = crack_midpoints(m, outline);
  double reach = -kInfinity, worst_off = 0;
  for (const Vec3& c : crack) {
    reach = std::max(reach, c.x());
    worst_off = std::max(worst_off, std::abs(c.y() - outline.centre_y()));
  }
  EXPECT_LT(worst_off, 0.03) << "a crack ran " << worst_off << " m from the centre line";
  EXPECT_GT(reach, outline.high.x() - 0.01) << "the crack stopped at x = " << reach;
  // Two large pieces: each half of the sheet, give or take the crack's wander and a few flakes at its end.
  const std::vector<double> areas = piece_areas(m);
  ASSERT_GE(areas.size(), 2u);
  EXPECT_GT(areas[0], 0.35 * sheet_area);
  EXPECT_GT(areas[1], 0.35 * sheet_area);
  std::printf("demo: %d cracks; %zu pieces, the two largest %.1f%% and %.1f%% of the sheet; crack within %.1f mm "
              "of the centre line\n",
              cracks, areas.size(), 100 * areas[0] / sheet_area, 100 * areas[1] / sheet_area, 1e3 * worst_off);
}

}  // namespace
}  // namespace arcsim
