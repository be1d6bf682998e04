// Wall time of one zone solve (physics/zone_solve.hpp) of ~100 nodes with a 1-ring support on sheets of 1k to
// 64k faces: the cost must follow the zone, not the mesh. Run with `make bench`
// (or `bin/arcsim-bench --benchmark_filter=ZoneSolve`); docs/benchmarks.md records the figures.
#include <benchmark/benchmark.h>

#include <cmath>

#include "physics/zone_fixtures.hpp"
#include "physics/zone_solve.hpp"

namespace arcsim {
namespace {

void BM_ZoneSolve(benchmark::State& state) {
  const int cells = static_cast<int>(std::lround(std::sqrt(state.range(0) / 2.0)));
  const testing::ZoneTestSheet sheet(cells);
  // The smallest edge-ring ball around the sheet's centre with at least 100 nodes.
  const int centre = sheet.node_at(cells / 2, cells / 2);
  std::vector<int> zone{centre};
  for (int rings = 1; zone.size() < 100; ++rings) zone = node_rings(sheet.mesh, {centre}, rings);
  CholeskySolver solver;
  const double dt = 1e-3;
  ZoneSolveOptions options;
  options.support_rings = 1;
  ZoneSolution solution;
  StepTiming timing;
  for (auto _ : state) {
    solution = solve_zone(sheet.mesh, sheet.materials, zone, sheet.loads, dt, solver, options);
    benchmark::DoNotOptimize(solution.v.data());
    timing.assembly += solution.timing.assembly;
    timing.factorization += solution.timing.factorization;
    timing.solve += solution.timing.solve;
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["assembly_us"] = 1e6 * timing.assembly / solves;
  state.counters["factor_us"] = 1e6 * timing.factorization / solves;
  state.counters["solve_us"] = 1e6 * timing.solve / solves;
  state.counters["faces"] = static_cast<double>(sheet.mesh.faces.size());
  state.counters["zone_nodes"] = static_cast<double>(solution.nodes.size());
  state.counters["support_nodes"] = static_cast<double>(solution.support_nodes.size());
  state.counters["elements"] = solution.face_elements + solution.bending_elements;
}
BENCHMARK(BM_ZoneSolve)->Arg(1000)->Arg(4000)->Arg(16000)->Arg(64000)->Unit(benchmark::kMicrosecond)
    ->MinTime(1.0);

}  // namespace
}  // namespace arcsim
