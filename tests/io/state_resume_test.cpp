// Resuming from a state file continues bit-identically: a sheet held by a moving corner handle (plus a moving
// obstacle) run for 40 steps straight must end in exactly the same bits as 20 steps, save, a fresh Simulation,
// load, and 20 more.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;
using testing::project_meshes;
using testing::TempDir;

// 10 x 10 cell sheet in the xy plane held at corner node 0, under gravity along -z; the handle and a strip
// obstacle below follow one keyframed motion, so handle targets and obstacle velocities change every step.
// Without contact the collision modules are off (fast under the sanitizers); with contact the sheet is thrown
// down onto the strip 5 mm below it, so proximity and impact-zone responses shape the state.
std::string held_sheet_scene(const fs::path& meshes, bool contact) {
  const std::string disable = contact ? R"(["remeshing"])" : R"(["remeshing", "proximity", "collision"])";
  const std::string velocity = contact ? "[0, 0, -1]" : "[0.1, 0, 0.2]";
  const std::string obstacle_at = contact ? "[0, 0.45, -0.005]" : "[0, 0, -0.5]";
  return R"({
    "frame_time": 0.01, "frame_steps": 4, "end_time": 10,
    "disable": )" + disable + R"(,
    "gravity": [0, 0, -9.8],
    "cloths": [{
      "mesh": ")" + (meshes / "square.obj").string() + R"(",
      "velocity": {"linear": )" + velocity + R"(, "angular": [0, 0, 0.5]},
      "materials": [{"thickness": 1e-3, "density": 500, "elastic_modulus": 2e7, "poisson_ratio": 0.3,
                     "damping": 1e-3}]
    }],
    "motions": [[
      {"time": 0, "transform": {"translate": [0, 0, 0]}},
      {"time": 0.05, "transform": {"translate": [0.05, 0.02, 0.03], "rotate": [10, 0, 0, 1]}},
      {"time": 0.2, "transform": {"translate": [0.1, -0.05, 0.1]}}
    ]],
    "handles": [{"nodes": [0], "motion": 0}],
    "obstacles": [{"mesh": ")" + (meshes / "strip.obj").string() + R"(",
                   "transform": {"translate": )" + obstacle_at + R"(}, "motion": 0}]
  })";
}

// Bitwise equality of two Eigen fixed-size vectors (memcmp: also tells -0 from 0).
bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }

class StateResume : public ::testing::Test {
 protected:
  void SetUp() override { scene_ = make_scene(false); }
  Scene make_scene(bool contact) {
    const fs::path meshes = project_meshes();
    EXPECT_FALSE(meshes.empty()) << "meshes/square.obj not found (run tests from the repository root)";
    EXPECT_FALSE(dir_.path.empty());
    const std::string scene_path = (dir_.path / "scene.json").string();
    std::ofstream(scene_path) << held_sheet_scene(meshes, contact);
    return load_scene(scene_path);
  }
  TempDir dir_;
  Scene scene_;
};
// The same with contact; slow under the sanitizers (collision detection every step).
class StateResumeSlow : public StateResume {};

void expect_same_state(const Simulation& a, const Simulation& b) {
  const double ta = a.time(), tb = b.time();
  EXPECT_EQ(std::memcmp(&ta, &tb, sizeof ta), 0) << ta << " vs " << tb;
  EXPECT_EQ(a.step(), b.step());
  EXPECT_EQ(a.frame(), b.frame());
  ASSERT_EQ(a.cloths.size(), b.cloths.size());
  for (size_t c = 0; c < a.cloths.size(); ++c) {
    const Mesh& ma = a.cloths[c].mesh;
    const Mesh& mb = b.cloths[c].mesh;
    ASSERT_EQ(ma.nodes.size(), mb.nodes.size());
    int differing = 0;
    for (size_t n = 0; n < ma.nodes.size(); ++n) {
      const Node& na = ma.nodes[n];
      const Node& nb = mb.nodes[n];
      const bool same = same_bits(na.x, nb.x) && same_bits(na.v, nb.v) && same_bits(na.x0, nb.x0) &&
                        same_bits(na.a, nb.a) && std::memcmp(&na.mass, &nb.mass, sizeof(double)) == 0;
      if (!same && ++differing <= 3)
        ADD_FAILURE() << "cloth " << c << " node " << n << " differs: x " << na.x.transpose() << " vs "
                      << nb.x.transpose() << ", v " << na.v.transpose() << " vs " << nb.v.transpose();
    }
    EXPECT_EQ(differing, 0);
  }
  ASSERT_EQ(a.obstacles.size(), b.obstacles.size());
  for (size_t o = 0; o < a.obstacles.size(); ++o)
    for (size_t n = 0; n < a.obstacles[o].mesh.nodes.size(); ++n) {
      const Node& na = a.obstacles[o].mesh.nodes[n];
      const Node& nb = b.obstacles[o].mesh.nodes[n];
      EXPECT_TRUE(same_bits(na.x, nb.x) && same_bits(na.x0, nb.x0) && same_bits(na.v, nb.v))
          << "obstacle " << o << " node " << n;
    }
}

// Runs 2 * half steps straight, and half + save + load into a fresh Simulation + half; the two must agree bit
// for bit. Returns the straight run's final positions of the sheet.
std::vector<Vec3> expect_resume_identical(const Scene& scene, const std::string& state, int half) {
  Simulation straight(scene);
  for (int i = 0; i < 2 * half; ++i) straight.advance_step();
  {
    Simulation first_half(scene);
    for (int i = 0; i < half; ++i) first_half.advance_step();
    save_state(first_half, state);
  }
  Simulation resumed(scene);
  load_state(resumed, state);
  EXPECT_EQ(resumed.step(), half);
  EXPECT_EQ(resumed.frame(), half / scene.frame_steps);
  for (int i = 0; i < half; ++i) resumed.advance_step();

  // The sheet really moved (so equality is not trivial).
  const Simulation fresh(scene);
  EXPECT_GT((straight.cloths[0].mesh.nodes[60].x - fresh.cloths[0].mesh.nodes[60].x).norm(), 1e-3);
  expect_same_state(straight, resumed);
  std::vector<Vec3> x;
  for (const Node& n : straight.cloths[0].mesh.nodes) x.push_back(n.x);
  return x;
}

TEST_F(StateResume, TwentyPlusTwentyStepsEqualFortyBitForBit) {
  expect_resume_identical(scene_, (dir_.path / "00005.state").string(), 20);
}

TEST_F(StateResumeSlow, WithContactAgainstAMovingObstacle) {
  const std::vector<Vec3> x = expect_resume_identical(make_scene(true), (dir_.path / "00002.state").string(), 8);
  // The strip, 5 mm below the middle row of the sheet, stopped that row: falling freely for 0.04 s from 1 m/s
  // it would be about 5 cm lower.
  EXPECT_GT(x[5 * 11 + 5].z(), -0.02);
}

TEST_F(StateResume, ResumingTwiceInARowStaysIdentical) {
  Simulation straight(scene_);
  for (int i = 0; i < 12; ++i) straight.advance_step();

  const std::string state = (dir_.path / "s.state").string();
  Simulation a(scene_);
  for (int i = 0; i < 4; ++i) a.advance_step();
  save_state(a, state);
  Simulation b(scene_);
  load_state(b, state);
  for (int i = 0; i < 4; ++i) b.advance_step();
  save_state(b, state);  // overwrites the earlier file (atomic rename)
  Simulation c(scene_);
  load_state(c, state);
  for (int i = 0; i < 4; ++i) c.advance_step();
  expect_same_state(straight, c);
  // Nothing but the state file is left in the folder: the temporary files were renamed away.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_.path)) files += entry.is_regular_file();
  EXPECT_EQ(files, 2);  // scene.json and s.state
}

TEST_F(StateResume, LoadingMarksPhysicsCachesDirty) {
  Simulation sim(scene_);
  sim.advance_step();
  EXPECT_FALSE(sim.cloths[0].elements_dirty);
  const std::string state = (dir_.path / "s.state").string();
  save_state(sim, state);
  load_state(sim, state);  // into a simulation whose caches are built
  EXPECT_TRUE(sim.cloths[0].elements_dirty);
  EXPECT_TRUE(sim.cloths[0].elements.faces.empty());
}

}  // namespace
}  // namespace arcsim
