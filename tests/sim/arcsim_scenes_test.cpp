// ARCSim 0.3's own cloth scenes run unmodified (remeshing off, as ARCSim's fixed mesh) for their first 2
// simulated seconds without NaN or blow-up. Skipped where the ARCSim example folder is absent.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "io/scene_parser.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

std::string arcsim_scenes() {
  const char* shared = std::getenv("ARCSIM_SHARED");
  return std::string(shared ? shared : "/work/shared") + "/arcsim-0.3-scenes";
}

class ArcsimClothScene : public ::testing::TestWithParam<const char*> {};

TEST_P(ArcsimClothScene, SlowRunsTwoSecondsWithoutRemeshing) {
  const std::string path = arcsim_scenes() + "/conf/" + GetParam() + ".json";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  scene.disabled.insert("remeshing");
  Simulation sim(scene);
  sim.set_end_time(2.0);
  while (!sim.finished()) sim.advance_frame();  // throws NumericalError on blow-up
  EXPECT_NEAR(sim.time(), 2.0, 1e-9);
  for (const Cloth& c : sim.cloths) {
    for (const Node& n : c.mesh.nodes) {
      ASSERT_TRUE(n.x.allFinite());
      // Nothing leaves the neighbourhood of the scene (a sheet of ~1 m).
      EXPECT_LT(n.x.norm(), 20.0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Arcsim, ArcsimClothScene, ::testing::Values("flag", "square", "square-pop"),
                         [](const auto& param) {
                           std::string name = param.param;
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

}  // namespace
}  // namespace arcsim
