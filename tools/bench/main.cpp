// The benchmark program (`make bench`): every tools/bench/*_bench.cpp registers its benchmarks with Google
// Benchmark; this file provides main().
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
