// Model library benchmarks: the full per-tick model update and the closure projection + eq. 7 inverse
// dynamics, each at a cycle of random closed-loop states (so branch prediction and caches see varying data).
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <random>
#include <string>
#include <vector>

#include "bench_stats.hpp"
#include "model/five_bar.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"

namespace {

using namespace mft::model;

struct BenchState {
  VectorQ q, qd, qdd;
  VectorC f_c;
};

const RobotDescription& benchRobot() {
  static const RobotDescription d = loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  return d;
}

// Closed-loop states with closure-consistent velocities and a consistent acceleration from eq. 1.
std::vector<BenchState> randomStates(const PlanarModel& model, int count) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<BenchState> states(count);
  ModelData data;
  for (BenchState& s : states) {
    const Eigen::Vector3d base(0.2 * unit(rng), 0.45 + 0.1 * unit(rng), 0.3 * unit(rng));
    const Eigen::Vector2d right = (0.33 + 0.08 * unit(rng)) * linkDirection(0.4 * unit(rng));
    const Eigen::Vector2d left = (0.33 + 0.08 * unit(rng)) * linkDirection(0.4 * unit(rng));
    s.q = closedLoopConfiguration(benchRobot(), base, right, left);
    VectorQ raw;
    for (int i = 0; i < kNq; ++i) raw(i) = 2.0 * unit(rng);
    updateModel(model, s.q, VectorQ::Zero(), &data);
    const Eigen::Matrix4d JJt = data.Jh * data.Jh.transpose();
    s.qd = raw - data.Jh.transpose() * JJt.llt().solve(data.Jh * raw);
    s.f_c << 30.0 * unit(rng), 100.0 + 80.0 * unit(rng), 30.0 * unit(rng), 100.0 + 80.0 * unit(rng);
    updateModel(model, s.q, s.qd, &data);
    VectorA tau;
    for (int i = 0; i < kNa; ++i) tau(i) = 20.0 * unit(rng);
    constrainedForwardDynamics(data, tau, s.f_c, &s.qdd, nullptr);
  }
  return states;
}

// One benchmark iteration per state of the cycle in turn: `tick(i)` on state i is timed, then `keep()` (untimed)
// keeps its results alive for the optimizer.
template <class Tick, class Keep>
void timeStateCycle(benchmark::State& state, std::size_t count, Tick&& tick, Keep&& keep) {
  mft::bench::LatencyRecorder latency;
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t i = k++ % count;
    latency.time([&] { tick(i); });
    keep();
    benchmark::ClobberMemory();
  }
  latency.report(state);
}

void BM_ModelUpdate(benchmark::State& state) {
  const PlanarModel model = buildBipedModel(benchRobot());
  const std::vector<BenchState> states = randomStates(model, 1024);
  ModelData data;
  timeStateCycle(
      state, states.size(), [&](std::size_t i) { updateModel(model, states[i].q, states[i].qd, &data); },
      [&] {
        benchmark::DoNotOptimize(data.M.data());
        benchmark::DoNotOptimize(data.h.data());
      });
}
BENCHMARK(BM_ModelUpdate);

// What the WBC does after the model update to turn a QP solution into torques (eq. 2-7), on models updated
// beforehand; with `with_update` the model update is timed too, into one ModelData: the whole model side of a tick.
void timeProjectionAndTorques(benchmark::State& state, bool with_update) {
  const PlanarModel model = buildBipedModel(benchRobot());
  const std::vector<BenchState> states = randomStates(model, 1024);
  std::vector<ModelData> datas(with_update ? 0 : states.size());
  for (std::size_t i = 0; i < datas.size(); ++i) updateModel(model, states[i].q, states[i].qd, &datas[i]);
  ModelData data;
  ClosureProjection proj;
  VectorA tau = VectorA::Zero();
  timeStateCycle(
      state, states.size(),
      [&](std::size_t i) {
        const BenchState& s = states[i];
        if (with_update) updateModel(model, s.q, s.qd, &data);
        const ModelData& d = with_update ? data : datas[i];
        closureProjection(d, &proj);
        tau = inverseDynamicsActuated(d, proj, s.qdd, s.qd, s.f_c);
      },
      [&] { benchmark::DoNotOptimize(tau.data()); });
}

void BM_ModelClosureProjectionInverseDynamics(benchmark::State& state) { timeProjectionAndTorques(state, false); }
BENCHMARK(BM_ModelClosureProjectionInverseDynamics);

void BM_ModelTick(benchmark::State& state) { timeProjectionAndTorques(state, true); }
BENCHMARK(BM_ModelTick);

}  // namespace
