// Stress case (issue 14): stiff glass at time steps 2x, 5x and 10x larger than ARCSim's sphere-break.json uses
// (5e-5 s). A 20 cm plate of that scene's glass (E = 50 GPa, 6 mm, bending_mult 100, toughness 2e7 Pa, fracture
// on, remeshing on) thrown edge-first at a floor at 5 m/s. At every step size the run must end with no NaN, a valid
// mesh, no node below the floor and no crossing triangles, in every frame.
//
// (It lands without cracking at these speeds; a plate that shatters, and a 5 ms step at which one collision step
// took 321 s, are in docs/stability.md.)
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/errors.hpp"

#include "collision/scene_fixtures.hpp"
#include "io/scene_parser.hpp"
#include "stress/repository.hpp"
#include "support/files.hpp"
#include "mesh/pieces.hpp"
#include "mesh/validate.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;
using namespace testing;
using arcsim::testing::TempDir;

std::string glass_plate_scene(const fs::path& root, const std::string& step) {
  const std::string square = (root / "meshes/square.obj").string(), ground = (root / "meshes/ground.obj").string();
  return R"({
    "timestep": )" + step + R"(, "duration": 0.06,
    "cloths": [{"mesh": ")" + square + R"(", "velocity": {"linear": [0, 0, -5]},
        "transform": {"translate": [-0.1, -0.1, 0.03], "rotate": [20, 1, 0, 0], "scale": 0.2},
        "materials": [{"damping": 1e-5, "thickness": 6e-3, "density": 2600, "elastic_modulus": 50e9,
                       "poisson_ratio": 0, "bending_mult": 100, "toughness": 2e7, "fracture_bending_mult": 0.8}],
        "remeshing": {"refine_angle": 0.2, "refine_compression": 1e-2, "refine_fracture": 0.3,
                      "size": [0.01, 0.05], "aspect_min": 0.3}}],
    "obstacles": [{"mesh": ")" + ground + R"(", "proxy": "floor", "transform": {"translate": [-1, -1, 0], "scale": 2}}],
    "gravity": [0, 0, -9.8],
    "disable": ["plasticity"],
    "magic": {"collision_stiffness": 1e13, "repulsion_thickness": 1e-4, "projection_thickness": 1e-5,
              "max_cracks": 400}
  })";
}

// The plate of glass_plate_scene dropped 3 cm from rest (0.77 m/s at landing) for `duration` s, with `extra`
// top-level keys (a JSON fragment ending in a comma, or "").
std::string dropped_plate_scene(const fs::path& root, const std::string& step, const std::string& duration,
                                const std::string& extra) {
  std::string scene = glass_plate_scene(root, step);
  const std::string from = R"("duration": 0.06,)", velocity = R"("velocity": {"linear": [0, 0, -5]},)";
  scene.replace(scene.find(from), from.size(), R"("duration": )" + duration + ", " + extra);
  scene.replace(scene.find(velocity), velocity.size(), "");
  return scene;
}

Simulation load_scene_text(const TempDir& dir, const std::string& text) {
  const fs::path path = dir.path / "scene.json";
  std::ofstream(path) << text;
  return Simulation(load_scene(path.string()));
}

TEST(StressGlassSlow, PlateThrownAtAFloorHoldsAtTwoFiveAndTenTimesArcsimsStep) {
  const fs::path root = repository_root("meshes/square.obj");
  ASSERT_FALSE(root.empty()) << "meshes/square.obj not found";
  const fs::path folder = fs::temp_directory_path() / ("arcsim-glass-" + std::to_string(::getpid()));
  fs::create_directories(folder);
  for (const char* step : {"1e-4", "2.5e-4", "5e-4"}) {
    SCOPED_TRACE(std::string("time step ") + step + " s");
    const fs::path path = folder / (std::string("glass-") + step + ".json");
    std::ofstream(path) << glass_plate_scene(root, step);
    Simulation sim(load_scene(path.string()));
    double lowest = 0;
    int crossing = 0, frames = 0;
    std::string invalid;
    while (!sim.finished()) {
      sim.advance_frame();
      ++frames;
      for (const Node& n : sim.cloths[0].mesh.nodes) lowest = std::min(lowest, n.x.z());
      crossing += count_intersecting_pairs(sim);
      if (invalid.empty()) invalid = check_mesh(sim.cloths[0].mesh);
      if (invalid.empty()) invalid = sim.nonfinite_state();
    }
    EXPECT_GT(frames, 100);
    EXPECT_EQ(invalid, "");
    EXPECT_GE(lowest, -1e-4) << "a node went through the floor";
    EXPECT_EQ(crossing, 0);
    // It reached the floor: the lowest edge started 3 cm up, moving down at 5 m/s.
    double lowest_now = 1;
    for (const Node& n : sim.cloths[0].mesh.nodes) lowest_now = std::min(lowest_now, n.x.z());
    EXPECT_LT(lowest_now, 5e-3);
  }
  fs::remove_all(folder);
}

// The plate dropped 3 cm (0.77 m/s at landing) with 5 ms steps, without adaptive stepping, to 0.12 s. The landing
// step's collision response projects the edge nodes by v dt = 3.8 mm and strains the glass over many rings
// (sigma+ up to 30 tau, 232 breaking nodes); fracture's virtual update in the default 3-ring zone cannot relax a
// strain its fixed support holds too, and the plate shatters into hundreds of pieces (at 1e-3 s steps it lands
// whole). Letting the zone grow while its support is stressed past half the toughness relaxes most of the
// artefact, not all of it: once the zone is the whole plate, the strain the floor's contacts hold remains (on
// some machines 0 cracks, on others 7 at sigma+ = 31 tau with the whole plate in the zone; the trajectory before
// the landing rounds differently between CPUs). Bounding the collision correction (the next test) is the cure.
TEST(StressGlassSlow, ZonesGrowingToACalmSupportRelaxMostOfAPlateLandingAtFiveMillisecondSteps) {
  const fs::path root = repository_root("meshes/square.obj");
  ASSERT_FALSE(root.empty()) << "meshes/square.obj not found";
  TempDir dir;
  auto cracks_with = [&](const std::string& fracture) {
    Simulation sim = load_scene_text(dir, dropped_plate_scene(root, "5e-3", "0.12", R"("fracture": )" + fracture + ","));
    int cracks = 0;
    while (!sim.finished()) {
      sim.advance_frame();
      for (const FractureStats& f : sim.fracture_stats) cracks += f.cracks;
    }
    EXPECT_EQ(check_mesh(sim.cloths[0].mesh), "");
    return cracks;
  };
  const int grown = cracks_with(R"({"max_zone_rings": 16, "support_stress": 0.5})");
  const int fixed_zone = cracks_with("{}");
  EXPECT_GT(fixed_zone, 100) << "the default zone no longer shatters the plate: the case proves nothing";
  EXPECT_LT(20 * grown, fixed_zone) << grown << " cracks with zone growth against " << fixed_zone << " without";
}

// The cause of that shattering, bounded directly: adaptive time stepping with max_correction = the repulsion
// thickness (1e-4 m) redoes in substeps only the steps whose collision response moves a node farther, i.e. the
// landing. The plate then lands whole at 2 ms and 5 ms steps, as it does at 1 ms, at a few retries' cost.
TEST(StressGlassSlow, BoundingTheCollisionCorrectionKeepsAPlateLandingAtLargeStepsWhole) {
  const fs::path root = repository_root("meshes/square.obj");
  ASSERT_FALSE(root.empty()) << "meshes/square.obj not found";
  TempDir dir;
  for (const char* step : {"2e-3", "5e-3"}) {
    SCOPED_TRACE(std::string("time step ") + step + " s");
    Simulation sim = load_scene_text(
        dir, dropped_plate_scene(root, step, "0.12",
                                 R"("adaptive_time_step": {"max_correction": 1e-4, "min_step": 1e-6},)"));
    int cracks = 0, retries = 0, crossing = 0;
    double lowest = 0;
    while (!sim.finished()) {
      sim.advance_frame();
      for (const FractureStats& f : sim.fracture_stats) cracks += f.cracks;
      retries += sim.time_step_stats.retries;
      for (const Node& n : sim.cloths[0].mesh.nodes) lowest = std::min(lowest, n.x.z());
      crossing += count_intersecting_pairs(sim);
    }
    EXPECT_EQ(cracks, 0);
    EXPECT_GE(retries, 1) << "no step was redone: the landing no longer needs it, and the case proves nothing";
    EXPECT_EQ(check_mesh(sim.cloths[0].mesh), "");
    EXPECT_GE(lowest, -1e-4);
    EXPECT_EQ(crossing, 0);
  }
}

// The same glass as a 20 cm plate dropped 3 cm onto a floor with a 5 ms step (100x ARCSim's): it shatters on
// landing into hundreds of shards whose smallest faces (down to the crack opening's sliver limit) make the
// implicit system too ill-conditioned to factorise (dt^2 K / m ~ 1e21 for one bending element): without adaptive
// time stepping the run stops with "not positive definite" (frame 33 of 60 on our machines). With it the failed
// steps are redone in substeps (down to 1/64 here) and the run ends, valid, above the floor and intersection-free.
TEST(StressGlassSlowCheck, PlateShatteringAtFiveMillisecondStepsEndsWithAdaptiveTimeStepping) {
  const fs::path root = repository_root("meshes/square.obj");
  ASSERT_FALSE(root.empty()) << "meshes/square.obj not found";
  TempDir dir;
  // The plate lands as the 2-face input refined by the first frame's remesh, as when this case was found.
  // Remeshed at start-up instead (magic.remesh_at_start, the default since 2026-12-06) it lands as a 32-face
  // plate and stops at step 27 on the collision budget at the finest substep: one of this drop's failing
  // neighbours (docs/stability.md, "the start-up remesh").
  std::string scene = dropped_plate_scene(root, "5e-3", "0.3", R"("adaptive_time_step": {"min_step": 1e-5},)");
  const std::string cracks = R"("max_cracks": 400})";
  scene.replace(scene.find(cracks), cracks.size(), R"("max_cracks": 400, "remesh_at_start": false})");
  Simulation sim = load_scene_text(dir, scene);
  double lowest = 0;
  int crossing = 0, retries = 0, finest = 0;
  std::string invalid, failure;
  try {
    while (!sim.finished()) {
      sim.advance_frame();
      retries += sim.time_step_stats.retries;
      finest = std::max(finest, sim.time_step_stats.level);
      for (const Node& n : sim.cloths[0].mesh.nodes) lowest = std::min(lowest, n.x.z());
      if (sim.frame() % 5 == 0) crossing += count_intersecting_pairs(sim);
      if (invalid.empty()) invalid = check_mesh(sim.cloths[0].mesh);
      if (invalid.empty()) invalid = sim.nonfinite_state();
    }
  } catch (const NumericalError& e) {
    failure = e.what();
  }
  EXPECT_EQ(failure, "");
  EXPECT_NEAR(sim.time(), 0.3, 1e-9);
  EXPECT_EQ(invalid, "");
  EXPECT_GE(lowest, -1e-4) << "a node went through the floor";
  EXPECT_EQ(crossing, 0);
  int faces = 0;
  for (const Face& f : sim.cloths[0].mesh.faces) faces += !f.dead;
  std::printf("glass plate at 5 ms: %d retries, finest level %d, %d faces at the end\n", retries, finest, faces);
}


// "A sheet torn into hundreds of pieces": the plate dropped 3 cm with 5 ms steps as above, at 1.5e6 Pa (0.075 of
// its toughness), fixed steps, to 0.12 s (docs/repro/glass-plate-shards.json with "toughness": 1.5e6 and
// "max_cracks": 2000). It shatters on landing into hundreds of pieces, many of a few faces, lying pressed against
// each other on the floor. What holds: every frame valid, finite, above the floor, free of crossing triangles;
// the run either ends or stops as issue 14 allows (a NumericalError naming its step), after the shattering.
// WHY 1.5e6 Pa: near the threshold the outcome is chaotic and machine-dependent (OpenBLAS picks other kernels
// on other CPUs, so rounding differs): at 3e6 Pa the plate gave 280 pieces on the AMD guest and 2 on the Intel
// one; at 1.5e6-2e6 Pa it gives 431-512 there, and 1e6 Pa 598 (docs/stability.md, 2026-12-06 afternoon).
TEST(StressShardsSlowCheck, PlateShatteredIntoAHundredPiecesStaysValidAndIntersectionFree) {
  const fs::path root = repository_root("meshes/square.obj");
  ASSERT_FALSE(root.empty()) << "meshes/square.obj not found";
  TempDir dir;
  std::string scene = dropped_plate_scene(root, "5e-3", "0.12", "");
  for (const auto& [from, to] : {std::pair<std::string, std::string>{R"("toughness": 2e7)", R"("toughness": 1.5e6)"},
                                 {R"("max_cracks": 400)", R"("max_cracks": 2000)"}})
    scene.replace(scene.find(from), from.size(), to);
  Simulation sim = load_scene_text(dir, scene);
  double lowest = 0;
  int crossing = 0, most_pieces = 0;
  std::string invalid, failure;
  try {
    while (!sim.finished()) {
      sim.advance_frame();
      for (const Node& n : sim.cloths[0].mesh.nodes) lowest = std::min(lowest, n.x.z());
      crossing += count_intersecting_pairs(sim);
      most_pieces = std::max(most_pieces, static_cast<int>(mesh_pieces(sim.cloths[0].mesh).size()));
      if (invalid.empty()) invalid = check_mesh(sim.cloths[0].mesh);
      if (invalid.empty()) invalid = sim.nonfinite_state();
    }
  } catch (const NumericalError& e) {
    failure = e.what();
  }
  std::printf("[ result ] shards: up to %d pieces, %d crossing pairs over the frames; %s\n", most_pieces, crossing,
              failure.empty() ? "ran to its end" : ("stopped: " + failure).c_str());
  if (!failure.empty()) {
    EXPECT_EQ(failure.rfind("step ", 0), 0u) << "a stop must name its step: " << failure;
    EXPECT_GT(most_pieces, 100) << "stopped before it shattered: " << failure;
  }
  EXPECT_EQ(invalid, "");
  EXPECT_GE(lowest, -1e-4) << "a node went through the floor";
  EXPECT_EQ(crossing, 0);
  EXPECT_GT(most_pieces, 100) << "it no longer shatters into hundreds of pieces: the case proves nothing";
}

}  // namespace
}  // namespace arcsim
