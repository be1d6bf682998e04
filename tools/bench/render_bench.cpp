// Off-screen rendering speed (arcsim replay): frames per second at 1280x720 for a ~20k-face cloth over a ground
// plane with shadows, as reported in docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cmath>

#include "render/render.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

void BM_RenderFrame(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(state.range(0) / 2.0)));
  Mesh mesh = testing::make_grid(n, n, 1.0, 1.0, testing::Diagonal::kAlternating);
  for (Node& node : mesh.nodes)
    node.x.z() = 0.5 + 0.1 * std::sin(6 * node.x.x()) * std::cos(4 * node.x.y());  // a draped, wavy sheet
  const std::vector<RenderMesh> cloths{render_mesh_from(mesh)};
  RenderOptions options;
  options.scene_bounds = bounds_of(cloths);
  options.wireframe = state.range(1) != 0;
  const int width = 1280, height = 720;
  const Camera camera = frame_camera(options.scene_bounds, double(width) / height, options.up);
  Renderer renderer(width, height);
  renderer.render(cloths, {}, camera, options);  // first frame compiles OSMesa's shaders
  for (auto _ : state) {
    renderer.render(cloths, {}, camera, options);
    benchmark::DoNotOptimize(renderer.rgba().data());
  }
  state.counters["faces"] = static_cast<double>(mesh.faces.size());
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                                      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderFrame)->Args({20000, 0})->Args({20000, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WritePng(benchmark::State& state) {
  std::vector<uint8_t> rgba(1280 * 720 * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<uint8_t>((i * 2654435761u) >> 24);
  for (auto _ : state) write_png("/tmp/arcsim-bench-frame.png", 1280, 720, rgba);
}
BENCHMARK(BM_WritePng)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace arcsim
