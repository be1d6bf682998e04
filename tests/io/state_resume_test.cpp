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

#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// The repository's meshes/ folder: from the working directory (the Makefile runs tests from the root), beside
// the bin/ folder of the test binary, or relative to this source file.
fs::path project_meshes() {
  std::error_code ignored;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ignored);
  for (const fs::path& dir : {fs::path("meshes"), exe.parent_path().parent_path() / "meshes",
                              fs::path(__FILE__).parent_path() / "../../meshes"})
    if (fs::exists(dir / "square.obj", ignored)) return fs::absolute(dir);
  return {};
}

// A fresh folder under the system temp folder, removed with everything in it at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "arcsim-state-XXXXXX").string();
    if (::mkdtemp(pattern.data())) path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path.empty()) fs::remove_all(path, ignored);
  }
};

// 10 x 10 cell sheet in the xy plane hanging from corner node 0 under gravity along -z; the handle and a strip
// obstacle below follow one keyframed motion, so handle targets and obstacle velocities change every step.
std::string hanging_sheet_scene(const fs::path& meshes) {
  return R"({
    "frame_time": 0.01, "frame_steps": 4, "end_time": 10,
    "disable": ["remeshing"],
    "gravity": [0, 0, -9.8],
    "cloths": [{
      "mesh": ")" + (meshes / "square.obj").string() + R"(",
      "velocity": {"linear": [0.1, 0, 0.2], "angular": [0, 0, 0.5]},
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
                   "transform": {"translate": [0, 0, -0.5]}, "motion": 0}]
  })";
}

// Bitwise equality of two Eigen fixed-size vectors (memcmp: also tells -0 from 0).
bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }

class StateResume : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path meshes = project_meshes();
    ASSERT_FALSE(meshes.empty()) << "meshes/square.obj not found (run tests from the repository root)";
    ASSERT_FALSE(dir_.path.empty());
    scene_path_ = (dir_.path / "scene.json").string();
    std::ofstream(scene_path_) << hanging_sheet_scene(meshes);
    scene_ = load_scene(scene_path_);
  }
  TempDir dir_;
  std::string scene_path_;
  Scene scene_;
};

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

TEST_F(StateResume, TwentyPlusTwentyStepsEqualFortyBitForBit) {
  Simulation straight(scene_);
  for (int i = 0; i < 40; ++i) straight.advance_step();

  const std::string state = (dir_.path / "00005.state").string();
  {
    Simulation first_half(scene_);
    for (int i = 0; i < 20; ++i) first_half.advance_step();
    save_state(first_half, state);
  }
  Simulation resumed(scene_);
  load_state(resumed, state);
  EXPECT_EQ(resumed.step(), 20);
  EXPECT_EQ(resumed.frame(), 5);
  for (int i = 0; i < 20; ++i) resumed.advance_step();

  // The sheet really moved (so equality is not trivial): the handle dragged it and gravity pulled it.
  const Simulation fresh(scene_);
  EXPECT_GT((straight.cloths[0].mesh.nodes[60].x - fresh.cloths[0].mesh.nodes[60].x).norm(), 1e-3);
  expect_same_state(straight, resumed);
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
