// Time per implicit step on flat sheets of 1k to 64k faces, split into assembly, factorisation and solve.
// Run with `make bench`; docs/benchmarks.md records the figures. ARCSIM_BENCH_PCG_TOLERANCE and
// ARCSIM_BENCH_PCG_MAX_ITERATIONS override the solver settings (for measuring them).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "physics/cloth_physics.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

// A square sheet of about `faces` faces, 1 m wide, slightly wavy so that bending and membrane terms are active,
// held at two corners and falling under gravity.
struct BenchSheet {
  Mesh mesh;
  std::vector<Material> materials;
  ElementCache cache;
  CholeskySolver solver;
  ExternalLoads loads;

  explicit BenchSheet(int faces) {
    const int n = static_cast<int>(std::lround(std::sqrt(faces / 2.0)));
    mesh = testing::make_grid(n, n, 1.0, 1.0, testing::Diagonal::kAlternating);
    Material m;
    m.thickness = 1e-4;
    m.density = 800;
    m.youngs_modulus = 4e9;
    m.poisson_ratio = 0.3;
    m.damping = 1e-4;
    materials = {m};
    for (Face& f : mesh.faces) f.thickness = m.thickness;
    for (Node& node : mesh.nodes) node.x.z() = 0.01 * std::sin(7 * node.x.x()) * std::cos(5 * node.x.y());
    update_node_masses(mesh, materials);
    build_element_cache(mesh, materials, cache);
    loads.gravity = Vec3(0, 0, -9.8);
    loads.springs.push_back({0, mesh.nodes[0].x, 1e3});
    loads.springs.push_back({n, mesh.nodes[n].x, 1e3});
  }
};

// The solver's default settings (physics/solver_settings.hpp); `direct` factorises at every step (the solver
// before 2026-12-05, and what systems below pcg_min_nodes get).
// `block_max_nodes` < 0 keeps the default choice between BlockCholesky and CHOLMOD.
void run_implicit_steps(benchmark::State& state, bool direct, int block_max_nodes = -1) {
  BenchSheet sheet(static_cast<int>(state.range(0)));
  SolverSettings settings;
  if (direct) settings.pcg_min_nodes = std::numeric_limits<int>::max();
  if (block_max_nodes >= 0) settings.block_max_nodes = block_max_nodes;
  if (const char* tolerance = std::getenv("ARCSIM_BENCH_PCG_TOLERANCE")) settings.pcg_tolerance = std::atof(tolerance);
  if (const char* iterations = std::getenv("ARCSIM_BENCH_PCG_MAX_ITERATIONS"))
    settings.pcg_max_iterations = std::atoi(iterations);
  sheet.solver.set_settings(settings);
  const double dt = 1e-3;
  implicit_euler_step(sheet.mesh, sheet.cache, sheet.solver, sheet.loads, dt);  // symbolic analysis, once
  StepTiming timing;
  for (auto _ : state) implicit_euler_step(sheet.mesh, sheet.cache, sheet.solver, sheet.loads, dt, &timing);
  const double steps = static_cast<double>(state.iterations());
  double max_residual = 0;
  for (double r : timing.residuals) max_residual = std::max(max_residual, r);
  state.counters["faces"] = static_cast<double>(sheet.mesh.faces.size());
  state.counters["nodes"] = static_cast<double>(sheet.mesh.nodes.size());
  state.counters["assembly_ms"] = 1e3 * timing.assembly / steps;
  state.counters["factor_ms"] = 1e3 * timing.factorization / steps;
  state.counters["solve_ms"] = 1e3 * timing.solve / steps;
  state.counters["assembly_share"] = timing.assembly / (timing.assembly + timing.factorization + timing.solve);
  state.counters["factorizations"] = timing.factorizations / steps;  // per step
  state.counters["pcg_iterations"] = timing.iterations / steps;      // per step
  state.counters["max_residual"] = max_residual;
}

void BM_ImplicitStep(benchmark::State& state) { run_implicit_steps(state, false); }
void BM_ImplicitStepDirect(benchmark::State& state) { run_implicit_steps(state, true); }
BENCHMARK(BM_ImplicitStep)->Arg(1000)->Arg(4000)->Arg(16000)->Arg(64000)->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK(BM_ImplicitStepDirect)->Arg(16000)->Arg(64000)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// Small systems: the same step with every system factorised by BlockCholesky (second argument 1) or by CHOLMOD
// (0), to place SolverSettings::block_max_nodes where the two cross.
void BM_ImplicitStepSmall(benchmark::State& state) {
  run_implicit_steps(state, true, state.range(1) ? std::numeric_limits<int>::max() : 0);
}
BENCHMARK(BM_ImplicitStepSmall)
    ->ArgsProduct({{100, 200, 400, 800, 1600, 3200, 6400}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(0.5);

}  // namespace
}  // namespace arcsim
