// Collision cost in whole time steps: a 1 m sheet of about 4k or 16k faces falling onto a sphere (radius
// 0.3 m, 320 faces) and draping over it, split into collision time (proximity terms + impact zones) and
// physics time (the implicit solve). Run with `make bench`; docs/benchmarks.md ("Collisions") records the
// figures.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "io/obj.hpp"
#include "sim/simulation.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// The repository's meshes/sphere.obj (the benchmark runs from the repository root, or next to bin/).
fs::path sphere_mesh() {
  std::error_code no_throw;
  const fs::path binary = fs::read_symlink("/proc/self/exe", no_throw);
  for (const fs::path& dir : {fs::path("meshes"), binary.parent_path().parent_path() / "meshes",
                              fs::path(__FILE__).parent_path() / "../../meshes"})
    if (fs::exists(dir / "sphere.obj", no_throw)) return dir / "sphere.obj";
  return {};
}

// A sheet of n x n cells (2 n^2 faces), flat in the xz plane, 5 mm above a sphere of radius 0.3 m and falling
// onto it at 0.5 m/s: contact starts within the first few steps. Fixed mesh, y up.
struct DrapeScene {
  fs::path dir;
  std::unique_ptr<Simulation> sim;

  explicit DrapeScene(int faces) {
    std::random_device rd;
    dir = fs::temp_directory_path() / ("arcsim-collision-bench-" + std::to_string(rd()));
    fs::create_directories(dir);
    const int n = static_cast<int>(std::lround(std::sqrt(faces / 2.0)));
    write_obj(testing::make_grid(n, n, 1.0, 1.0, testing::Diagonal::kAlternating), (dir / "sheet.obj").string());

    Scene s;
    s.path = "collision-bench";
    s.frame_time = s.step_time = 2e-3;
    s.frame_steps = 1;
    s.end_time = kInfinity;
    s.gravity = Vec3(0, -9.8, 0);
    s.wind.density = 0;
    s.disabled = {"remeshing", "plasticity", "fracture", "strainlimiting", "separation", "popfilter"};
    ClothSpec cloth;
    cloth.mesh = (dir / "sheet.obj").string();
    cloth.transform.translation = Vec3(-0.5, 0.305, 0.5);
    cloth.transform.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitX()));
    cloth.velocity.linear = Vec3(0, -0.5, 0);
    Material m;  // a vinyl-like film: 0.2 mm, 0.26 kg/m^2, E = 20 MPa
    m.name = "bench sheet";
    m.thickness = 2e-4;
    m.density = 1300;
    m.youngs_modulus = 2e7;
    m.poisson_ratio = 0.45;
    m.damping = 1e-3;
    cloth.materials = {m};
    s.cloths.push_back(cloth);
    ObstacleSpec sphere;
    sphere.mesh = sphere_mesh().string();
    sphere.transform.scale = 0.3;
    s.obstacles.push_back(sphere);
    sim = std::make_unique<Simulation>(s);
  }
  ~DrapeScene() {
    sim.reset();
    std::error_code ignore;
    fs::remove_all(dir, ignore);
  }
};

void BM_CollisionDrapeStep(benchmark::State& state) {
  if (sphere_mesh().empty()) {
    state.SkipWithError("meshes/sphere.obj not found (run from the repository root)");
    return;
  }
  DrapeScene scene(static_cast<int>(state.range(0)));
  Simulation& sim = *scene.sim;
  for (int i = 0; i < 10; ++i) sim.advance_step();  // first contact and the solver's symbolic analysis
  sim.times.clear();
  for (auto _ : state) sim.advance_step();
  const double steps = static_cast<double>(state.iterations());
  state.counters["faces"] = static_cast<double>(sim.cloths[0].mesh.faces.size());
  state.counters["collision_ms"] = 1e3 * sim.times.collision / steps;
  state.counters["physics_ms"] = 1e3 * sim.times.physics / steps;
  state.counters["collision_share"] = sim.times.collision / (sim.times.collision + sim.times.physics);
}
// A fixed number of steps (the sheet drapes further with each one), so that every run measures the same motion.
BENCHMARK(BM_CollisionDrapeStep)->Arg(4000)->Iterations(40)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CollisionDrapeStep)->Arg(16000)->Iterations(15)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arcsim
