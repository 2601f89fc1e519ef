// QP solver latency on the 200 shared WBC instances (shared/qp/instances/seq_1600_1799), solved in file-name
// order, one solve per benchmark iteration, only the solve() call timed (mean / p50 / p99 / max in us).
// mft-qp bench reports the same with the per-step minimum over passes (QP.md section 1).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "bench_stats.hpp"
#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_solver.hpp"

namespace {

using namespace mft::qp;

const std::vector<QpInstance>& qpInstances() {
  static const std::vector<QpInstance> instances = [] {
    std::vector<QpInstance> v;
    try {
      for (const std::string& f : listQpInstanceFiles(std::string(MFT_SHARED_DIR) + "/qp/instances/seq_1600_1799"))
        v.push_back(readQpInstance(f));
    } catch (const QpIoError&) {
      v.clear();
    }
    return v;
  }();
  return instances;
}

void solveSequence(benchmark::State& state, bool warm) {
  const auto& instances = qpInstances();
  if (instances.empty()) {
    state.SkipWithError("no QP instances in shared/qp/instances/seq_1600_1799");
    return;
  }
  const QpProblem& first = instances.front().problem;
  GoldfarbIdnaniSolver solver(first.n, first.neq, first.nin);
  solver.options().warm_start = warm;
  QpSolution solution;
  solution.resize(first.n, first.neq, first.nin);
  mft::bench::LatencyRecorder recorder;
  std::size_t k = 0;
  long failures = 0;
  for (auto _ : state) {
    if (k == instances.size()) {
      k = 0;
      solver.clearWarmStart();  // the sequence restarts: no meaningful previous active set
    }
    QpStatus status = QpStatus::Optimal;
    recorder.time([&] { status = solver.solve(instances[k].problem, &solution); });
    failures += status == QpStatus::Optimal ? 0 : 1;
    benchmark::DoNotOptimize(solution.x.data());
    ++k;
  }
  recorder.report(state);
  state.counters["failures"] = static_cast<double>(failures);
}

void BM_QpGoldfarbIdnaniCold(benchmark::State& state) { solveSequence(state, false); }
void BM_QpGoldfarbIdnaniWarm(benchmark::State& state) { solveSequence(state, true); }

// 10 passes over the 200 instances.
BENCHMARK(BM_QpGoldfarbIdnaniCold)->Iterations(2000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QpGoldfarbIdnaniWarm)->Iterations(2000)->Unit(benchmark::kMicrosecond);

}  // namespace
