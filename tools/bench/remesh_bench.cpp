// Cost of adaptive remeshing in a draping scene (issue 4 acceptance 6): a 0.6 m stiff-fabric sheet falls onto a
// sphere of radius 0.12 m (collisions on), 12 frames of 20 ms. BM_DrapeAdaptive remeshes at every frame end
// from a coarse 10 cm grid; BM_DrapeFixedHighRes runs the same scene with `fixed_high_res_mesh` (one uniform
// refinement to the same size_min, then no remeshing). Counters: seconds per frame, the share of step time
// spent remeshing, and the final face count. Run with `make bench`; docs/benchmarks.md records the figures.
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <filesystem>

#include "io/obj.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "sim/remesh_cloth.hpp"
#include "sim/simulation.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kBallRadius = 0.12;  // m
constexpr double kSizeMin = 0.015;    // m, remeshing size_min of both variants
constexpr int kFrames = 12;

struct DrapeFiles {
  std::string sheet, ball;
  DrapeFiles() {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "arcsim-remesh-bench";
    std::filesystem::create_directories(dir);
    const std::string tag = std::to_string(::getpid());
    sheet = (dir / ("sheet-" + tag + ".obj")).string();
    ball = (dir / ("ball-" + tag + ".obj")).string();
    write_plain_obj(testing::make_grid(6, 6, 0.6, 0.6), sheet);
    write_plain_obj(remesh_test::make_icosphere(kBallRadius, 3), ball);
  }
  ~DrapeFiles() {
    std::filesystem::remove(sheet);
    std::filesystem::remove(ball);
  }
};

Scene drape_scene(const DrapeFiles& files, bool fixed_high_res) {
  Scene scene;
  scene.path = "remesh-bench.json";
  scene.frame_time = 0.02;
  scene.frame_steps = 4;
  scene.step_time = scene.frame_time / scene.frame_steps;
  ClothSpec cloth;
  cloth.mesh = files.sheet;
  cloth.transform.translation = Vec3(-0.3, -0.3, kBallRadius + 0.01);
  Material m = remesh_test::cotton();  // made stiffer: 1 mm, 20 MPa
  m.thickness = 1e-3;
  m.youngs_modulus = 2e7;
  m.damping = 1e-3;
  cloth.materials = {m};
  cloth.remeshing.refine_angle = 0.3;
  cloth.remeshing.size_min = kSizeMin;
  cloth.remeshing.size_max = 0.2;
  cloth.remeshing.aspect_min = 0.2;
  cloth.remeshing.has_size = cloth.remeshing.has_aspect_min = true;
  scene.cloths.push_back(cloth);
  ObstacleSpec ball;
  ball.mesh = files.ball;
  scene.obstacles.push_back(ball);
  scene.gravity = Vec3(0, 0, -9.8);
  scene.magic.repulsion_thickness = 5e-3;
  scene.magic.fixed_high_res_mesh = fixed_high_res;
  scene.disabled = {"plasticity", "fracture"};
  return scene;
}

void run_drape(benchmark::State& state, bool fixed_high_res) {
  const DrapeFiles files;
  const Scene scene = drape_scene(files, fixed_high_res);
  double step_seconds = 0, remesh_seconds = 0, faces = 0;
  for (auto _ : state) {
    Simulation sim(scene);
    for (int frame = 0; frame < kFrames; ++frame) sim.advance_frame();
    const ModuleTimes& t = sim.times;
    step_seconds += t.physics + t.collision + t.remeshing + t.plasticity + t.fracture;
    remesh_seconds += t.remeshing;
    faces = mesh_size_stats(sim.cloths[0].mesh).faces;
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["s_per_frame"] = step_seconds / (runs * kFrames);
  state.counters["remesh_share"] = step_seconds > 0 ? remesh_seconds / step_seconds : 0;
  state.counters["faces"] = faces;
}

void BM_DrapeAdaptive(benchmark::State& state) { run_drape(state, false); }
void BM_DrapeFixedHighRes(benchmark::State& state) { run_drape(state, true); }
BENCHMARK(BM_DrapeAdaptive)->Unit(benchmark::kSecond)->Iterations(2);
BENCHMARK(BM_DrapeFixedHighRes)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace arcsim
