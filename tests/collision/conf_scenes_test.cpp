// The collision scenes of conf/ (issue 3), loaded through the real scene parser and run to their end. After
// every frame: no cloth node deeper than 0.1 mm inside an obstacle (or under the floor proxy), and no
// intersecting pair of non-adjacent triangles (exact test, cloth-cloth and cloth-obstacle). Each scene also
// checks that the contact it is about happened. Each takes 0.2-1.5 s optimised (2 threads, loaded machine)
// and many times that under the sanitizers, hence the Slow suite.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "collision/penetration.hpp"
#include "collision/scene_fixtures.hpp"
#include "io/scene_parser.hpp"

namespace arcsim {
namespace {

using namespace testing;

// The repository's conf/ folder (tests run from the repository root; also found next to bin/ or this file).
fs::path project_conf() {
  std::error_code no_throw;
  const fs::path binary = fs::read_symlink("/proc/self/exe", no_throw);
  for (const fs::path& candidate : {fs::path("conf"), binary.parent_path().parent_path() / "conf",
                                    fs::path(__FILE__).parent_path() / "../../conf"})
    if (fs::exists(candidate / "drape-sphere.json", no_throw)) return candidate;
  return {};
}

struct SceneRun {
  double deepest = 0;       // deepest penetration over all frames (m)
  int intersecting = 0;     // intersecting triangle pairs summed over all frames
  int first_bad_frame = -1;
  int frames = 0;
  std::unique_ptr<Simulation> sim;  // at the end of the run (null if the scene was not found)
};

// Runs the scene file to its end, checking every frame; `each_frame` sees the simulation after each frame.
template <class F>
SceneRun run_scene_file(const std::string& name, F each_frame) {
  SceneRun checks;
  const fs::path conf = project_conf();
  if (conf.empty()) {
    ADD_FAILURE() << "conf/" << name << " not found";
    return checks;
  }
  checks.sim = std::make_unique<Simulation>(load_scene((conf / name).string()));
  Simulation& sim = *checks.sim;
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    sim.advance_frame();
    const double depth = deepest_penetration(sim);
    const int crossing = count_intersecting_pairs(sim);
    if ((depth > 1e-4 || crossing > 0) && checks.first_bad_frame < 0) checks.first_bad_frame = sim.frame();
    checks.deepest = std::max(checks.deepest, depth);
    checks.intersecting += crossing;
    ++checks.frames;
    each_frame(sim);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ timing ] %s: %d frames, %d steps, %.2f s wall (collision %.2f s, physics %.2f s); deepest %.2e m\n",
              name.c_str(), checks.frames, sim.step(), seconds, sim.times.collision, sim.times.physics,
              checks.deepest);
  return checks;
}

void expect_clean(const SceneRun& c) {
  EXPECT_GT(c.frames, 10);
  EXPECT_LE(c.deepest, 1e-4);
  EXPECT_EQ(c.intersecting, 0) << "first bad frame " << c.first_bad_frame;
}

TEST(ConfScenesSlow, DrapeSphere) {
  const Vec3 center = Vec3::Zero();
  const double radius = 0.3;
  const SceneRun c = run_scene_file("drape-sphere.json", [](const Simulation&) {});
  ASSERT_TRUE(c.sim);
  const Simulation* sim = c.sim.get();
  expect_clean(c);
  // Draped: the middle node rests on top of the sphere (within a few repulsion thicknesses) and the corners
  // hang below its equator (the sheet's folds and the air drag keep them from hanging straight down in 1 s).
  const Mesh& m = sim->cloths[0].mesh;
  EXPECT_NEAR((m.nodes[60].x - center).norm(), radius, 5e-3);
  for (int corner : {0, 10, 110, 120}) EXPECT_LT(m.nodes[corner].x.y(), -0.05) << "corner " << corner;
}

TEST(ConfScenesSlow, DropFloor) {
  double first_contact = kInfinity;
  const SceneRun c = run_scene_file("drop-floor.json", [&](const Simulation& s) {
    if (lowest_cloth_y(s) < 5e-3) first_contact = std::min(first_contact, s.time());
  });
  ASSERT_TRUE(c.sim);
  const Simulation* sim = c.sim.get();
  expect_clean(c);
  // Free fall from 0.3 m takes 0.25 s; then it lies flat on the floor, within a few repulsion thicknesses.
  EXPECT_GT(first_contact, 0.2);
  EXPECT_LT(first_contact, 0.35);
  for (const Node& n : sim->cloths[0].mesh.nodes) EXPECT_LT(n.x.y(), 5e-3);
}

// Pairs of nodes at least `apart` (m) apart along the strip's rest shape but within `distance` in space.
int folded_node_pairs(const Mesh& m, double distance, double apart) {
  int n = 0;
  for (size_t i = 0; i < m.nodes.size(); ++i)
    for (size_t j = i + 1; j < m.nodes.size(); ++j)
      if ((m.verts[m.nodes[i].verts[0]].u - m.verts[m.nodes[j].verts[0]].u).norm() > apart &&
          (m.nodes[i].x - m.nodes[j].x).norm() < distance)
        ++n;
  return n;
}

TEST(ConfScenesSlow, StripFold) {
  int most_folded = 0;
  const SceneRun c = run_scene_file("strip-fold.json", [&](const Simulation& s) {
    most_folded = std::max(most_folded, folded_node_pairs(s.cloths[0].mesh, 0.03, 0.2));
  });
  ASSERT_TRUE(c.sim);
  const Simulation* sim = c.sim.get();
  expect_clean(c);
  // The 1 m strip ends in a heap on the floor: nothing higher than 15 cm, and many nodes lie within 3 cm of
  // nodes 20 cm or more away along the strip (the mesh spacing is 5 cm): layers on top of each other.
  double top = -kInfinity;
  for (const Node& n : sim->cloths[0].mesh.nodes) top = std::max(top, n.x.y());
  EXPECT_LT(top, 0.15);
  EXPECT_GT(most_folded, 30);
}

TEST(ConfScenesSlow, FastSphere) {
  double furthest = 0;  // furthest any sheet node was pushed along the sphere's path (m)
  double sphere_z = 0;
  const SceneRun c = run_scene_file("fast-sphere.json", [&](const Simulation& s) {
    for (const Node& n : s.cloths[0].mesh.nodes) furthest = std::max(furthest, n.x.z());
    if (s.time() < 0.05 + 1e-9) {
      // While it moves, the sphere's centre (mean of its nodes) runs at 10 m/s from z = -0.3.
      Vec3 mean = Vec3::Zero();
      for (const Node& n : s.obstacles[0].mesh.nodes) mean += n.x;
      sphere_z = mean.z() / s.obstacles[0].mesh.nodes.size();
      EXPECT_NEAR(sphere_z, -0.3 + 10 * s.time(), 1e-6) << "t = " << s.time();
    }
  });
  ASSERT_TRUE(c.sim);
  expect_clean(c);
  // The sphere carried the middle of the sheet with it: to z = 0.5 + 0.15 (its far side) less the gap.
  EXPECT_GT(furthest, 0.6);
}

}  // namespace
}  // namespace arcsim
