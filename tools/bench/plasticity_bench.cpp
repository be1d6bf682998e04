// Cost of plasticity per step on conf/metal-crumple-remesh.json (issue 6 acceptance 5): an aluminium sheet
// dented by a sphere, remeshed at every frame end, run to its end with the plastic transfer of remeshing set to
// the local embedding (paper §5.2) or to naive interpolation. Counters, per time step: the whole step
// (ms_step), the flow rules (ms_flow, Simulation::times.plasticity), the frame-end remeshing (ms_remesh) and the
// plastic transfer inside it (ms_transfer: embeddings, split placement, Eq. 11 read-back or interpolation;
// RemeshStats::plastic_seconds); also the final face count, the plastic work of the whole run (J) and the
// deepest and highest points of the sheet at the end (dent_mm below its flat start: the dent it keeps;
// rise_mm above it: none expected, the sphere only pushes down). Run from the repository
// root: `./bin/arcsim-bench --benchmark_filter=MetalCrumple`.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "io/scene_parser.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

constexpr const char* kScene = "conf/metal-crumple-remesh.json";

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void run_crumple(benchmark::State& state, bool embedding) {
  if (!std::filesystem::exists(kScene)) {
    state.SkipWithError("conf/metal-crumple-remesh.json not found (run from the repository root)");
    return;
  }
  Scene scene = load_scene(kScene);
  for (ClothSpec& cloth : scene.cloths) cloth.remeshing.plastic_embedding = embedding;
  double step_seconds = 0, transfer_seconds = 0, work = 0, dent = 0, rise = 0;
  ModuleTimes times;
  long steps = 0;
  int faces = 0;
  for (auto _ : state) {
    Simulation sim(scene);
    while (!sim.finished()) {
      const auto start = std::chrono::steady_clock::now();
      sim.advance_frame();
      step_seconds += seconds_since(start);
      steps += sim.frame_steps();
      for (const RemeshStats& r : sim.remesh_stats) transfer_seconds += r.plastic_seconds;
      for (double w : sim.plastic_work) work += w;
    }
    times = sim.times;
    faces = 0;
    dent = rise = 0;
    for (const Face& f : sim.cloths[0].mesh.faces) faces += f.dead ? 0 : 1;
    for (const Node& n : sim.cloths[0].mesh.nodes) {
      dent = std::max(dent, -n.x.z());
      rise = std::max(rise, n.x.z());
    }
  }
  const double per_step = 1e3 / std::max(steps, 1L);  // ms per step
  state.counters["ms_step"] = step_seconds * per_step;
  state.counters["ms_flow"] = times.plasticity * per_step * state.iterations();
  state.counters["ms_remesh"] = times.remeshing * per_step * state.iterations();
  state.counters["ms_transfer"] = transfer_seconds * per_step;
  state.counters["faces"] = faces;
  state.counters["work_J"] = work / state.iterations();
  state.counters["dent_mm"] = 1e3 * dent;
  state.counters["rise_mm"] = 1e3 * rise;
}

void BM_MetalCrumpleEmbedding(benchmark::State& state) { run_crumple(state, true); }
void BM_MetalCrumpleInterpolate(benchmark::State& state) { run_crumple(state, false); }

BENCHMARK(BM_MetalCrumpleEmbedding)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_MetalCrumpleInterpolate)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace arcsim
