// Adaptive time stepping (scene key adaptive_time_step, issue 14): a step whose dynamics fail is redone from its
// start in 2, 4, 8, ... substeps; a run that would stop goes on; the time step grows back; a step that fails at
// the smallest substep stops with a message naming it; and with nothing to trigger it the run is bit-identical
// to one without it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "io/errors.hpp"
#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

using testing::TempDir;

// A 10 cm sheet held at one corner. With E = 1e20 Pa a 10 ms step is beyond double precision
// (dt^2 K / m ~ 1e18: CHOLMOD reports the matrix not positive definite); 16 substeps bring it to ~4e15.
std::string stiff_sheet_scene(const std::string& adaptive, double youngs_modulus, double end_time) {
  const std::string mesh = (testing::project_meshes() / "square.obj").string();
  return R"({"frame_time": 0.01, "frame_steps": 1, "end_time": )" + std::to_string(end_time) + R"(,
    "cloths": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.1, "rotate": [30, 1, 0.2, 0]},
      "materials": [{"thickness": 1e-3, "density": 800, "elastic_modulus": )" + std::to_string(youngs_modulus) +
         R"(, "poisson_ratio": 0.3}]}],
    "handles": [{"nodes": [0]}],
    "gravity": [0, 0, -9.8], "disable": ["remeshing"])" + adaptive + "}";
}

Simulation load(TempDir& dir, const std::string& text) {
  const std::string path = (dir.path / "scene.json").string();
  std::ofstream(path) << text;
  return Simulation(load_scene(path));
}

std::string run_error(Simulation& sim) {
  try {
    while (!sim.finished()) sim.advance_frame();
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

TEST(AdaptiveTimeStep, AStepThatCannotBeFactorisedIsRedoneInSubstepsAndTheStepGrowsBack) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  Simulation fixed = load(dir, stiff_sheet_scene("", 1e20, 0.1));
  const std::string fixed_error = run_error(fixed);
  EXPECT_NE(fixed_error.find("not positive definite"), std::string::npos) << "the case no longer fails";
  // Without adaptive stepping the failure names its step (issue 14: the step, the cause, what to try).
  EXPECT_EQ(fixed_error.rfind("step 1 (t = 0 to 0.01 s): ", 0), 0u) << fixed_error;

  Simulation adaptive = load(dir, stiff_sheet_scene(R"(, "adaptive_time_step": {"grow_after": 2})", 1e20, 0.1));
  int retries = 0, finest = 0, coarsest_after = 99;
  std::string problem;
  try {
    while (!adaptive.finished()) {
      adaptive.advance_frame();
      retries += adaptive.time_step_stats.retries;
      finest = std::max(finest, adaptive.time_step_stats.level);
      if (adaptive.frame() > 1) coarsest_after = std::min(coarsest_after, adaptive.substep_level());
      if (adaptive.time_step_stats.retries > 0) {
        EXPECT_NE(adaptive.time_step_stats.cause.find("not positive definite"), std::string::npos);
      }
    }
  } catch (const NumericalError& e) {
    problem = e.what();
  }
  EXPECT_EQ(problem, "");
  EXPECT_NEAR(adaptive.time(), 0.1, 1e-12);
  EXPECT_GE(retries, 2);
  EXPECT_GE(finest, 2);
  EXPECT_LE(finest, 6);
  // After two good steps at a level it tries the next coarser one (and falls back when that fails again).
  EXPECT_LT(coarsest_after, finest);
  EXPECT_EQ(adaptive.nonfinite_state(), "");
}

TEST(AdaptiveTimeStep, AStepThatFailsAtTheSmallestSubstepStopsWithAMessageNamingIt) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  Simulation sim = load(dir, stiff_sheet_scene(R"(, "adaptive_time_step": {"min_step": 0.004})", 1e20, 0.1));
  const std::string error = run_error(sim);
  EXPECT_NE(error.find("step 1 (t = 0 to 0.01 s) failed at the smallest substep 0.005 s "
                       "(adaptive_time_step.min_step 0.004 s)"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("not positive definite"), std::string::npos) << error;
  EXPECT_NE(error.find("try a smaller min_step or time step"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

// A sheet falling between two fixed plates 0.5 mm apart, closer than the 1 mm collision gap: once it reaches the
// lower plate no position meets both gaps, so its collision response falls back at that moment of the step at
// every substep length. Refining cannot remove that; the step is retaken at the streak's level and the fallback
// held (counted), and the run goes on to its end with the sheet between the plates, where it used to stop at the
// smallest substep.
TEST(AdaptiveTimeStep, AFallbackNoSubstepRemovesIsHeldAndTheRunGoesOn) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  const std::string mesh = (testing::project_meshes() / "square.obj").string();
  const std::string scene = R"({"frame_time": 0.01, "frame_steps": 1, "end_time": 0.03,
    "cloths": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.1, "translate": [0, 0, 0.25e-3]},
      "materials": [{"thickness": 1e-4, "density": 800, "elastic_modulus": 1e6, "poisson_ratio": 0.3}]}],
    "obstacles": [
      {"mesh": ")" + mesh + R"(", "transform": {"scale": 0.3, "translate": [-0.1, -0.1, 0]}},
      {"mesh": ")" + mesh + R"(", "transform": {"scale": 0.3, "translate": [-0.1, -0.1, 0.5e-3]}}],
    "gravity": [0, 0, -9.8], "disable": ["remeshing", "proximity"],
    "magic": {"repulsion_thickness": 1e-2, "projection_thickness": 1e-3},
    "adaptive_time_step": {"min_step": 3.90625e-5}})";
  Simulation sim = load(dir, scene);
  int held = 0;
  std::string problem;
  try {
    while (!sim.finished()) {
      sim.advance_frame();
      held += sim.time_step_stats.held_steps;
    }
  } catch (const NumericalError& e) {
    problem = e.what();
  }
  EXPECT_EQ(problem, "");
  EXPECT_NEAR(sim.time(), 0.03, 1e-12);
  EXPECT_GE(held, 1);
  for (const Node& n : sim.cloths[0].mesh.nodes) {
    EXPECT_GT(n.x.z(), 0.0);
    EXPECT_LT(n.x.z(), 0.5e-3);
  }
}

// max_motion: a falling sheet's step is split so that no node moves farther per substep; the fall still
// matches the closed form (implicit Euler's error shrinks with the substeps).
TEST(AdaptiveTimeStep, MotionPerSubstepStaysWithinMaxMotion) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  const std::string mesh = (testing::project_meshes() / "square.obj").string();
  Simulation sim = load(dir, R"({"frame_time": 0.01, "frame_steps": 1, "end_time": 0.5,
    "cloths": [{"mesh": ")" + mesh + R"(", "transform": {"scale": 0.1},
      "materials": [{"thickness": 1e-3, "density": 800, "elastic_modulus": 1e6, "poisson_ratio": 0.3}]}],
    "gravity": [0, 0, -9.8], "wind": {"density": 0}, "disable": ["remeshing"],
    "adaptive_time_step": {"max_motion": 0.002}})");
  const double z0 = sim.cloths[0].mesh.nodes[0].x.z();
  int substeps = 0;
  while (!sim.finished()) {
    sim.advance_frame();
    substeps += sim.time_step_stats.substeps;
    // v dt per substep, at the frame's end speed (the fastest in it).
    EXPECT_LE(sim.cloths[0].mesh.nodes[0].v.norm() * sim.time_step_stats.smallest, 0.002 * (1 + 1e-9));
  }
  // 4.9 m/s at the end: 0.049 m per 10 ms step, so 32 substeps per step at the end (max_motion 2 mm).
  EXPECT_EQ(sim.time_step_stats.level, 5);
  EXPECT_GT(substeps, 400);
  const double fallen = z0 - sim.cloths[0].mesh.nodes[0].x.z();
  // Fixed 10 ms steps fall g dt^2 N (N + 1) / 2 = 1.2495 m (2% long); the substeps bring it within 0.5%.
  EXPECT_NEAR(fallen, 0.5 * 9.8 * 0.25, 0.005 * 0.5 * 9.8 * 0.25);
}

// With nothing to trigger it (no failure, no fallback, no motion bound), the adaptive run takes the same steps
// and gives bit-identical positions.
TEST(AdaptiveTimeStep, UntriggeredItChangesNothing) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  Simulation plain = load(dir, stiff_sheet_scene("", 1e6, 0.2));
  Simulation adaptive = load(dir, stiff_sheet_scene(R"(, "adaptive_time_step": true)", 1e6, 0.2));
  EXPECT_EQ(run_error(plain), "");
  EXPECT_EQ(run_error(adaptive), "");
  ASSERT_EQ(plain.cloths[0].mesh.nodes.size(), adaptive.cloths[0].mesh.nodes.size());
  for (size_t i = 0; i < plain.cloths[0].mesh.nodes.size(); ++i) {
    EXPECT_EQ(plain.cloths[0].mesh.nodes[i].x, adaptive.cloths[0].mesh.nodes[i].x) << "node " << i;
    EXPECT_EQ(plain.cloths[0].mesh.nodes[i].v, adaptive.cloths[0].mesh.nodes[i].v) << "node " << i;
  }
  EXPECT_EQ(adaptive.substep_level(), 0);
}

// The level is part of the saved state: a run saved while its steps are split and resumed continues exactly as
// the uninterrupted one.
TEST(AdaptiveTimeStep, ResumedMidRunItContinuesBitIdentically) {
  ASSERT_FALSE(testing::project_meshes().empty());
  TempDir dir;
  const std::string scene = stiff_sheet_scene(R"(, "adaptive_time_step": {"grow_after": 3})", 1e20, 0.08);
  Simulation whole = load(dir, scene);
  EXPECT_EQ(run_error(whole), "");
  Simulation first = load(dir, scene);
  for (int f = 0; f < 4; ++f) first.advance_frame();
  ASSERT_GT(first.substep_level(), 0) << "saved where no step is split: the test would prove nothing";
  const std::string state = (dir.path / "mid.state").string();
  save_state(first, state);
  Simulation resumed = load(dir, scene);
  load_state(resumed, state);
  EXPECT_EQ(resumed.substep_level(), first.substep_level());
  EXPECT_EQ(resumed.steps_at_substep_level(), first.steps_at_substep_level());
  EXPECT_EQ(run_error(resumed), "");
  for (size_t i = 0; i < whole.cloths[0].mesh.nodes.size(); ++i)
    EXPECT_EQ(whole.cloths[0].mesh.nodes[i].x, resumed.cloths[0].mesh.nodes[i].x) << "node " << i;
}

}  // namespace
}  // namespace arcsim
