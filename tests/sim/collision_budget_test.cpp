// The collision budget (scene key collision_budget, issue 14): a step whose collision response spends more work
// units than collision_budget x cloth nodes fails like any numerical failure, naming the step, the cause (with
// the zones it had) and what to try; under adaptive time stepping it is redone in substeps. A scene that stays
// within its budget (all normal ones: the default is far above what they spend) is bit-identical to one without
// a budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "io/errors.hpp"
#include "io/scene_parser.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

using testing::TempDir;

// A 10 cm sheet (121 nodes) thrown at 3 m/s onto a plate 1 cm below it, with 10 ms steps: it crosses the plate
// within the first step, before proximity sees it coming, so that step's collision response has to stop it.
std::string thrown_sheet_scene(const std::string& extra) {
  const std::string mesh = (testing::project_meshes() / "square.obj").string();
  return R"({"frame_time": 0.01, "frame_steps": 1, "end_time": 0.05,
    "cloths": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.1, "translate": [-0.05, -0.05, 0.01]},
      "velocity": {"linear": [0, 0, -3]},
      "materials": [{"thickness": 1e-3, "density": 800, "elastic_modulus": 1e7, "poisson_ratio": 0.3}]}],
    "obstacles": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.4, "translate": [-0.2, -0.2, 0]}}],
    "gravity": [0, 0, -9.8], "disable": ["remeshing"])" + extra + "}";
}

Simulation load(TempDir& dir, const std::string& text) {
  const std::string path = (dir.path / "scene.json").string();
  std::ofstream(path) << text;
  return Simulation(load_scene(path));
}

TEST(CollisionBudget, IsAParsedSceneKeyWithADefault) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  EXPECT_EQ(load(dir, thrown_sheet_scene("")).scene().collision_budget, kDefaultCollisionBudget);
  EXPECT_EQ(load(dir, thrown_sheet_scene(R"(, "collision_budget": 2.5e4)")).scene().collision_budget, 2.5e4);
  EXPECT_THROW(load(dir, thrown_sheet_scene(R"(, "collision_budget": 0)")), InputError);
  EXPECT_THROW(load(dir, thrown_sheet_scene(R"(, "collision_budget": "lots")")), InputError);
}

// The sheet's landing step with a budget of 1 work unit per node: the step fails with a message that names it,
// says why (the budget, with the zones), and what to try; the frames before it are untouched.
TEST(CollisionBudget, AStepThatExceedsItsBudgetFailsNamingTheStepTheCauseAndWhatToTry) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  // Where the landing is, and what it costs with the default budget.
  Simulation free = load(dir, thrown_sheet_scene(""));
  int landing = 0;
  double work = 0;
  while (!free.finished() && landing == 0) {
    free.advance_frame();
    if (free.collision_totals().impacts > 0) {
      landing = free.frame();
      work = free.collision_totals().largest_work;
    }
    free.clear_collision_totals();
  }
  ASSERT_GT(landing, 0) << "the sheet never reached the plate: the case proves nothing";
  EXPECT_LT(work, 0.05 * kDefaultCollisionBudget * 121) << "a simple landing comes near the default budget";

  Simulation starved = load(dir, thrown_sheet_scene(R"(, "collision_budget": 1)"));
  std::string message;
  try {
    while (!starved.finished()) starved.advance_frame();
  } catch (const NumericalError& e) {
    message = e.what();
  }
  EXPECT_EQ(message.rfind("step " + std::to_string(landing) + " (t = ", 0), 0u) << message;
  EXPECT_NE(message.find("collision handling did not converge within its budget"), std::string::npos) << message;
  EXPECT_NE(message.find("collision_budget 1 per node x 121 nodes"), std::string::npos) << message;
  EXPECT_NE(message.find("impact zones, the largest "), std::string::npos) << message;
  EXPECT_NE(message.find("try adaptive_time_step, a smaller time step, or a larger collision_budget"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(starved.frame(), landing - 1);
}

// Under adaptive time stepping the failed step is redone in substeps, and a budget that no substep can meet ends
// the run at min_step, naming the step and the budget.
TEST(CollisionBudget, UnderAdaptiveTimeSteppingTheStepIsRedoneAndFailsAtTheSmallestSubstep) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  Simulation sim =
      load(dir, thrown_sheet_scene(R"(, "collision_budget": 1, "adaptive_time_step": {"min_step": 2.5e-3})"));
  std::string message;
  try {
    while (!sim.finished()) sim.advance_frame();
  } catch (const NumericalError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("failed at the smallest substep 0.0025 s"), std::string::npos) << message;
  EXPECT_NE(message.find("collision handling did not converge within its budget"), std::string::npos) << message;
  EXPECT_GE(sim.time_step_stats.retries, 2);
  EXPECT_NE(sim.time_step_stats.cause.find("within its budget"), std::string::npos);
}

// A scene that stays within its budget runs bit-identically with any larger one (the budget only stops work; it
// never changes what the optimiser does before that).
TEST(CollisionBudget, AStepWithinItsBudgetIsBitIdenticalToOneWithout) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  Simulation normal = load(dir, thrown_sheet_scene(""));
  Simulation unlimited = load(dir, thrown_sheet_scene(R"(, "collision_budget": 1e300)"));
  double largest = 0;
  while (!normal.finished()) {
    normal.advance_frame();
    unlimited.advance_frame();
    largest = std::max(largest, normal.collision_totals().largest_work);
    const auto& a = normal.cloths[0].mesh.nodes;
    const auto& b = unlimited.cloths[0].mesh.nodes;
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].x, b[i].x) << "frame " << normal.frame() << " node " << i;
      ASSERT_EQ(a[i].v, b[i].v) << "frame " << normal.frame() << " node " << i;
    }
  }
  EXPECT_GT(largest, 0) << "no collision response ran: the case proves nothing";
}

}  // namespace
}  // namespace arcsim
