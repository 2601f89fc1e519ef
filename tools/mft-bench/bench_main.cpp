// mft-bench: every benchmark of the project in one Google Benchmark executable.
// Benchmarks report mean, p99 and max through the statistics registered by each case (see bench_stats.hpp).
#include <benchmark/benchmark.h>

#include <cstring>
#include <iostream>
#include "common/tool_io.hpp"

static int toolMain(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::cout << "mft-bench: all benchmarks of mft-wbc (Google Benchmark).\n"
                   "Usage: mft-bench [--benchmark_filter=REGEX] [--json] [google-benchmark options]\n"
                   "  --json          machine-readable output (same as --benchmark_format=json)\n"
                   "Each case reports per-iteration time; cases that time a control tick report mean, p99 and\n"
                   "max in microseconds as counters (mean_us, p99_us, max_us).\n"
                   "Build in Release (scripts/build.sh release) before quoting numbers.\n";
      return 0;
    }
    if (std::strcmp(argv[i], "--json") == 0) argv[i] = const_cast<char*>("--benchmark_format=json");
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-bench", [&] { return toolMain(argc, argv); });
}
