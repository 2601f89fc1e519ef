// QP solver latency on the project's QP instance set (tests/data/qp, docs/reference/qp-instances.md), solved in file-name
// order, one solve per benchmark iteration, only the solve() call timed (mean / p50 / p99 / max in us).
// mft-qp bench reports the same with the per-step minimum over passes (docs/reference/qp.md#measuring-solve-time).
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
      for (const std::string& f : listQpInstanceFiles(MFT_QP_INSTANCE_DIR))
        v.push_back(readQpInstance(f));
    } catch (const QpIoError&) {
      v.clear();
    }
    return v;
  }();
  return instances;
}

// Instances are named <run>_<tick>.
std::string runOf(const QpInstance& inst) { return inst.name.substr(0, inst.name.rfind('_')); }

void solveSequence(benchmark::State& state, bool warm) {
  const auto& instances = qpInstances();
  if (instances.empty()) {
    state.SkipWithError("no QP instances in " MFT_QP_INSTANCE_DIR);
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
    if (k == instances.size()) k = 0;
    // A new run (or the sequence restarting) has no meaningful previous active set.
    if (k == 0 || runOf(instances[k]) != runOf(instances[k - 1])) solver.clearWarmStart();
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

// About 10 passes over the instance set.
BENCHMARK(BM_QpGoldfarbIdnaniCold)->Iterations(2000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QpGoldfarbIdnaniWarm)->Iterations(2000)->Unit(benchmark::kMicrosecond);

}  // namespace
