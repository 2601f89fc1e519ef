#pragma once
// The mft-qp subcommands. Each returns the process exit code: 0 ok, 1 solver failures, 2 bad input.
#include <string>

namespace mft::tools {

struct BenchOptions {
  std::string dir;
  bool json = false;
  bool warm = false;
  int passes = 3;
  int cpu = -1;  // pin to this CPU if >= 0
};

struct SolveOptions {
  std::string file;
  bool json = false;
};

int runBench(const BenchOptions& options);
int runSolve(const SolveOptions& options);

}  // namespace mft::tools
