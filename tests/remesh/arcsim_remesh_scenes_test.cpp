// ARCSim 0.3's own cloth scenes with remeshing on (their intended mode): each runs its first 5 simulated seconds
// (sphere.json: to its end) without NaN, blow-up, invalid mesh or intersecting triangles. square-pop (ARCSim's test of popping without its pop filter) is also
// checked for popping: the world surface may change by remeshing only a small fraction of the sheet's motion
// per frame. Skipped where the ARCSim example folder is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <tuple>

#include "collision/distance.hpp"
#include "collision/scene_fixtures.hpp"
#include "io/scene_parser.hpp"
#include "mesh/validate.hpp"
#include "sim/remesh_cloth.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

std::string scene_path(const std::string& name) {
  const char* shared = std::getenv("ARCSIM_SHARED");
  return std::string(shared ? shared : "/work/shared") + "/arcsim-0.3-scenes/conf/" + name + ".json";
}

// Runs ARCSim's scene `name` with remeshing to `end_time` (s), checking every frame: no NaN or blow-up (a
// NumericalError), a valid mesh, no node flung far, and no intersecting triangles every 5th frame and at the end.
void run_checked(const char* name, double end_time) {
  const std::string path = scene_path(name);
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  ASSERT_TRUE(scene.enabled("remeshing"));
  Simulation sim(scene);
  sim.set_end_time(end_time);
  // The input mesh first: remeshing adapts it already at the end of frame 1.
  std::vector<int> face_counts{static_cast<int>(sim.cloths[0].mesh.faces.size())};
  while (!sim.finished()) {
    sim.advance_frame();  // throws NumericalError on blow-up
    for (size_t c = 0; c < sim.cloths.size(); ++c) {
      const Mesh& m = sim.cloths[c].mesh;
      ASSERT_EQ(check_mesh(m), "") << "frame " << sim.frame();
      for (const Node& n : m.nodes) ASSERT_LT(n.x.norm(), 20.0) << "frame " << sim.frame();
    }
    face_counts.push_back(mesh_size_stats(sim.cloths[0].mesh).faces);
    // No cloth triangle crosses another or an obstacle's (exact test; every 5th frame and the last, as the
    // all-pairs count costs about as much as a frame).
    if (sim.frame() % 5 == 0 || sim.finished()) {
      ASSERT_EQ(testing::count_intersecting_pairs(sim), 0) << "frame " << sim.frame();
    }
  }
  EXPECT_NEAR(sim.time(), end_time, 1e-9);
  // Remeshing adapted the 2-triangle (square) or coarse (flag) input.
  EXPECT_GT(*std::max_element(face_counts.begin(), face_counts.end()), 4 * face_counts.front() / 3);
  const ModuleTimes& t = sim.times;
  const double total = t.physics + t.collision + t.remeshing;
  const MeshSizeStats s = mesh_size_stats(sim.cloths[0].mesh);
  std::printf("%s: %d faces, edges %.4f / %.4f / %.4f m; time physics %.2f s, collision %.2f s, remeshing %.2f s "
              "(%.0f%%)\n",
              name, s.faces, s.edge_min, s.edge_median, s.edge_max, t.physics, t.collision, t.remeshing,
              100 * t.remeshing / total);
}

std::string param_name(const ::testing::TestParamInfo<const char*>& param) {
  std::string name = param.param;
  for (char& ch : name)
    if (ch == '-') ch = '_';
  return name;
}

class ArcsimRemeshScene : public ::testing::TestWithParam<const char*> {};

TEST_P(ArcsimRemeshScene, SlowCheckRunsFiveSecondsWithRemeshing) { run_checked(GetParam(), 5.0); }

INSTANTIATE_TEST_SUITE_P(Arcsim, ArcsimRemeshScene, ::testing::Values("square", "square-pop", "flag"), param_name);

// Scenes run to their own end time (issue 17: every ARCSim scene must). sphere.json (10 s) stopped at 2.76 s with
// "not positive definite" before commit ecd4ba2 (a node in two slots of a bending element lost its cross blocks);
// its last 3 s, the sphere dragging and releasing the cloth, are the heaviest (~8k faces). About 10 minutes.
class ArcsimRemeshSceneToItsEnd : public ::testing::TestWithParam<const char*> {};

TEST_P(ArcsimRemeshSceneToItsEnd, SlowCheckRunsToItsEndWithRemeshing) {
  const std::string path = scene_path(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  const double end_time = load_scene(path).end_time;
  ASSERT_GT(end_time, 5.0);
  run_checked(GetParam(), end_time);
}

INSTANTIATE_TEST_SUITE_P(Arcsim, ArcsimRemeshSceneToItsEnd, ::testing::Values("sphere"), param_name);

// Largest distance from the nodes of `from` to the surface of `to` (m), over the nodes farther than `skip` from
// every node of `to` being exact vertices of it (those are unchanged by the remesh and at distance 0). Triangles
// are bucketed in a grid of cell `cell` (m); points farther than a cell from `to` are not expected here.
double max_distance_to_surface(const Mesh& from, const Mesh& to, double cell) {
  std::map<std::tuple<int, int, int>, std::vector<int>> grid;
  auto key = [&](const Vec3& p) {
    return std::make_tuple(static_cast<int>(std::floor(p.x() / cell)), static_cast<int>(std::floor(p.y() / cell)),
                           static_cast<int>(std::floor(p.z() / cell)));
  };
  for (size_t f = 0; f < to.faces.size(); ++f) {
    if (to.faces[f].dead) continue;
    Vec3 lo = Vec3::Constant(kInfinity), hi = Vec3::Constant(-kInfinity);
    for (int i = 0; i < 3; ++i) {
      lo = lo.cwiseMin(to.nodes[to.face_node(static_cast<int>(f), i)].x);
      hi = hi.cwiseMax(to.nodes[to.face_node(static_cast<int>(f), i)].x);
    }
    const auto [x0, y0, z0] = key(lo);
    const auto [x1, y1, z1] = key(hi);
    for (int x = x0; x <= x1; ++x)
      for (int y = y0; y <= y1; ++y)
        for (int z = z0; z <= z1; ++z) grid[{x, y, z}].push_back(static_cast<int>(f));
  }
  double worst = 0;
  for (const Node& n : from.nodes) {
    if (n.dead) continue;
    const auto [cx, cy, cz] = key(n.x);
    double best = kInfinity;
    for (int x = cx - 1; x <= cx + 1; ++x)
      for (int y = cy - 1; y <= cy + 1; ++y)
        for (int z = cz - 1; z <= cz + 1; ++z) {
          const auto it = grid.find({x, y, z});
          if (it == grid.end()) continue;
          for (int f : it->second)
            best = std::min(best, vertex_face_closest(n.x, to.nodes[to.face_node(f, 0)].x,
                                                      to.nodes[to.face_node(f, 1)].x,
                                                      to.nodes[to.face_node(f, 2)].x).distance);
        }
    worst = std::max(worst, std::isfinite(best) ? best : cell);
  }
  return worst;
}

// square-pop: a sheet of paper held at its four corners and pushed together (buckling), remeshed every frame
// without ARCSim's pop filter. Remeshing runs here as in Simulation (remesh + topology_changed at every frame end)
// so that the world surface can be compared before and after it. A pop is remeshing moving the surface: new or
// reprojected nodes away from the old surface, removed nodes away from the new one. The largest such jump over
// the frames must stay below 10% of the typical motion: the median over frames of the largest node
// displacement in a frame, during the pushing (t in [1, 5] s).
TEST(ArcsimRemeshPop, SlowSquarePopDoesNotPop) {
  const std::string path = scene_path("square-pop");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  scene.disabled.insert("remeshing");  // done below, the same way
  Simulation sim(scene);
  sim.set_end_time(5.0);
  const RemeshOptions options = remesh_options(scene);
  std::vector<double> motion, jumps;
  while (!sim.finished()) {
    Cloth& cloth = sim.cloths[0];
    std::vector<Vec3> start;
    for (const Node& n : cloth.mesh.nodes) start.push_back(n.x);
    sim.advance_frame();
    double moved = 0;
    for (size_t i = 0; i < start.size(); ++i) moved = std::max(moved, (cloth.mesh.nodes[i].x - start[i]).norm());
    const Mesh before = cloth.mesh;
    sim.topology_changed(0, edited(remesh(cloth, nullptr, options)));
    ASSERT_EQ(check_mesh(cloth.mesh), "");
    if (sim.time() < 1.0) continue;  // the handles start moving at t = 1 s
    motion.push_back(moved);
    jumps.push_back(std::max(max_distance_to_surface(cloth.mesh, before, 0.05),
                             max_distance_to_surface(before, cloth.mesh, 0.05)));
  }
  ASSERT_FALSE(motion.empty());
  std::vector<double> sorted = motion;
  std::sort(sorted.begin(), sorted.end());
  const double typical = sorted[sorted.size() / 2];
  const double worst = *std::max_element(jumps.begin(), jumps.end());
  std::printf("square-pop: typical motion per frame %.3g m, largest remeshing jump %.3g m (%.1f%%)\n", typical,
              worst, 100 * worst / typical);
  EXPECT_GT(typical, 0);
  EXPECT_LT(worst, 0.1 * typical);
}

// ARCSim remeshes every cloth once at start-up (relax_initial_state), so its frame 0 of square.json holds 128
// faces (its 00000.bin), not the input's 4. Ours does the same (magic.remesh_at_start): the sheet at rest is
// sized before the first step, so no step folds the 4-face input along its diagonals (which the first frame's
// remesh then refined to 1024 faces and the next coarsened back to ~220). The sheet stays nearly flat and at
// rest, and the handled corners keep their nodes.
TEST(ArcsimRemeshStartUp, SquareIsSizedAtRestBeforeTheFirstStep) {
  const std::string path = scene_path("square");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  const Simulation sim(scene);
  const Mesh& m = sim.cloths[0].mesh;
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(mesh_size_stats(m).faces, 128);  // ARCSim 0.3.1's frame 0, measured
  // Nearly flat: the reprojection places new nodes at their local equilibrium under gravity, up to 1.1 mm
  // below the input's plane z = 0 (measured), while the input's own nodes stay in it.
  for (const Node& n : m.nodes) {
    EXPECT_LE(n.x.z(), 0.0);
    EXPECT_GT(n.x.z(), -2e-3);
    EXPECT_EQ(n.v, Vec3::Zero());
  }
  ASSERT_EQ(sim.handles.size(), 2u);
  for (const Handle& h : sim.handles) {
    ASSERT_EQ(h.nodes.size(), 2u);
    for (size_t k = 0; k < h.nodes.size(); ++k) {
      ASSERT_GE(h.nodes[k], 0);
      ASSERT_LT(h.nodes[k], static_cast<int>(m.nodes.size()));
      EXPECT_EQ(m.nodes[h.nodes[k]].x, h.anchors[k]);
      EXPECT_NEAR(std::abs(h.anchors[k].x()), 0.5, 1e-12);
      EXPECT_NEAR(std::abs(h.anchors[k].y()), 0.5, 1e-12);
    }
  }
  // Switched off, the first step sees the input mesh.
  scene.magic.remesh_at_start = false;
  const Simulation unsized(scene);
  EXPECT_EQ(mesh_size_stats(unsized.cloths[0].mesh).faces, 4);
}

}  // namespace
}  // namespace arcsim
