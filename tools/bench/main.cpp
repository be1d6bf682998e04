// The benchmark program (`make bench`): every tools/bench/*_bench.cpp registers its benchmarks with Google
// Benchmark; this file provides main(), with the heap set up as the arcsim program sets it (app/heap.hpp).
#include <benchmark/benchmark.h>

#include "app/heap.hpp"

int main(int argc, char** argv) {
  arcsim::keep_freed_memory_in_heap();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
