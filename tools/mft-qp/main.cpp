// mft-qp: the project's Goldfarb–Idnani QP solver on WBCQP v1 instance files (docs/reference/qp-instances.md#file-format).
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "qp_commands.hpp"
#include "common/tool_io.hpp"

namespace {

const char* kUsage =
    "mft-qp: solve WBCQP v1 instance files with the project's Goldfarb-Idnani QP solver.\n"
    "Usage:\n"
    "  mft-qp bench DIR [--json] [--passes N] [--warm] [--cpu K]\n"
    "      Solves every *.txt instance of DIR in file-name order, N passes (default 3), and reports failures,\n"
    "      max |x - x_ref|, max KKT residual, active-set mismatches vs active_ref and the solve time in us\n"
    "      (solver call only; per step the minimum over passes; mean / p50 / p99 / max, plus the raw max).\n"
    "      --warm: each pass warm-starts every solve from the previous step's active set.\n"
    "      --cpu K: pin the process to CPU K (otherwise not pinned). Memory is locked when permitted.\n"
    "  mft-qp solve FILE [--json]\n"
    "      Solves one instance and prints status, objective, accuracy, KKT residuals and the active set.\n"
    "  mft-qp --help\n"
    "Exit codes: 0 success, 1 a solve did not reach Optimal or its answer failed the KKT check (status\n"
    "\"unverified\"), 2 bad arguments or unreadable input (also a non-finite or asymmetric H).\n";

int usageError(const std::string& message) {
  std::cerr << "mft-qp: " << message << "\n(see mft-qp --help)\n";
  return 2;
}

bool parseInt(const char* s, int* out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (*s == '\0' || *end != '\0' || v < 0 || v > 1000000) return false;
  *out = static_cast<int>(v);
  return true;
}

}  // namespace

static int toolMain(int argc, char** argv) {
  if (argc < 2) return usageError("missing command");
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::cout << kUsage;
    return 0;
  }
  for (int i = 2; i < argc; ++i)
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::cout << kUsage;
      return 0;
    }
  try {
    if (cmd == "bench") {
      mft::tools::BenchOptions o;
      for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--json") {
          o.json = true;
        } else if (a == "--warm") {
          o.warm = true;
        } else if (a == "--passes" || a == "--cpu") {
          int v = 0;
          if (i + 1 >= argc || !parseInt(argv[i + 1], &v)) return usageError(a + " needs a non-negative integer");
          ++i;
          if (a == "--passes") {
            if (v < 1) return usageError("--passes must be at least 1");
            o.passes = v;
          } else {
            o.cpu = v;
          }
        } else if (!a.empty() && a[0] == '-') {
          return usageError("unknown option " + a);
        } else if (o.dir.empty()) {
          o.dir = a;
        } else {
          return usageError("bench takes one DIR");
        }
      }
      if (o.dir.empty()) return usageError("bench needs a DIR");
      return mft::tools::runBench(o);
    }
    if (cmd == "solve") {
      mft::tools::SolveOptions o;
      for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--json")
          o.json = true;
        else if (!a.empty() && a[0] == '-')
          return usageError("unknown option " + a);
        else if (o.file.empty())
          o.file = a;
        else
          return usageError("solve takes one FILE");
      }
      if (o.file.empty()) return usageError("solve needs a FILE");
      return mft::tools::runSolve(o);
    }
  } catch (const std::exception& e) {
    std::cerr << "mft-qp: " << e.what() << "\n";
    return 2;
  }
  return usageError("unknown command '" + cmd + "'");
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-qp", [&] { return toolMain(argc, argv); });
}
