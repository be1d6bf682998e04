// The simulation's collision settings: material neighbours (a crack's lips, collision/proximity.hpp) repel only
// within the lip gap in scenes that can crack; in every other scene all parts of a sheet repel at the full
// repulsion thickness, as in ARCSim, so that scenes without fracture keep their frames.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "io/scene_parser.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

using testing::TempDir;

Simulation sheet(TempDir& dir, const std::string& toughness) {
  const std::string mesh = (testing::project_meshes() / "square.obj").string();
  const std::string path = (dir.path / "scene.json").string();
  std::ofstream(path) << R"({"frame_time": 0.01, "frame_steps": 1, "end_time": 0.01,
    "cloths": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.1},
      "materials": [{"thickness": 1e-3, "density": 800, "elastic_modulus": 1e6, "poisson_ratio": 0.3)" +
                             toughness + R"(}],
      "remeshing": {"refine_fracture": 0, "size": [0.01, 0.05]}}],
    "disable": ["remeshing"], "magic": {"repulsion_thickness": 2e-3}})";
  return Simulation(load_scene(path));
}

TEST(CollisionSettings, MaterialNeighboursRepelWithinTheLipGapOnlyInScenesThatCanCrack) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  const Simulation plain = sheet(dir, "");
  EXPECT_DOUBLE_EQ(plain.collision_settings().repulsion_thickness, 2e-3);
  EXPECT_DOUBLE_EQ(plain.collision_settings().neighbour_thickness, 2e-3);

  const Simulation brittle = sheet(dir, R"(, "toughness": 1e5)");
  EXPECT_DOUBLE_EQ(brittle.collision_settings().repulsion_thickness, 2e-3);
  EXPECT_DOUBLE_EQ(brittle.collision_settings().neighbour_thickness, brittle.fracture.opening.lip_gap);
  EXPECT_LT(brittle.collision_settings().neighbour_thickness, 2e-3);
}

}  // namespace
}  // namespace arcsim
