// Cost of the mesh validity checks (issue 15: speed is measured here, not asserted in tests):
// BM_ValidateTriangles checks an OBJ-style triangle list of an n x n grid (2 n^2 triangles) as the reader does;
// BM_CheckMesh runs check_mesh, which the step runs after every topology phase, on an n x n grid mesh. Both
// should grow linearly with the face count (Google Benchmark fits the complexity).
#include <benchmark/benchmark.h>

#include "mesh/mesh_fixtures.hpp"
#include "mesh/validate.hpp"

namespace arcsim {
namespace {

void BM_ValidateTriangles(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  TriangleInput in;
  in.node_count = static_cast<size_t>((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      in.vert_u.emplace_back(i, j, 0);
      in.vert_node.push_back(test::grid_node(n, i, j));
    }
  in.tris = test::grid_triangles(n, n, [&](int i, int j) { return test::grid_node(n, i, j); });
  for (auto _ : state) validate_triangles(in, "bench.obj");
  state.SetComplexityN(static_cast<int64_t>(in.tris.size()));
}
BENCHMARK(BM_ValidateTriangles)->RangeMultiplier(2)->Range(50, 200)->Unit(benchmark::kMillisecond)->Complexity();

void BM_CheckMesh(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Mesh m = test::make_flat_grid(n, n);
  for (auto _ : state) benchmark::DoNotOptimize(check_mesh(m));
  state.SetComplexityN(static_cast<int64_t>(m.faces.size()));
}
BENCHMARK(BM_CheckMesh)->RangeMultiplier(2)->Range(50, 200)->Unit(benchmark::kMillisecond)->Complexity();

}  // namespace
}  // namespace arcsim
