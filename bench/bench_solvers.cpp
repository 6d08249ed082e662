// Placeholder until the benchmark suite lands (being written now).
#include <benchmark/benchmark.h>
BENCHMARK_MAIN();
