// Whole-body controller tick latency: one WholeBodyController::update() per benchmark iteration (model update,
// closure projection, assembly, QP solve, eq. 7 inverse dynamics, safety stage), timed per call (mean / p50 /
// p99 / max in us). Inputs: 2000 precomputed closed-loop states (config/robot.yaml, config/mft_space.yaml,
// config/wbc.yaml): base height 0.39-0.44 m, so the legs move in and out of the MFT polytope, with sinusoidal
// perturbations of base and feet, and a contact schedule alternating double support, right stance and left
// stance every 100 ticks; the references hold 0.40 m / level pitch and move the swing foot.
// Counters: mean_us/p50_us/p99_us/max_us of the whole tick (timed outside update()), max_min3_us = worst
// state of the per-state minimum over the 10 passes, qp_mean_us/qp_max_us = the solver call alone.
// Run: build/<dir>/bin/mft-bench --benchmark_filter=BM_WbcTick   (pin with taskset -c 1 on a busy host)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bench_stats.hpp"
#include "model/mft_polytope.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"
#include "wbc/whole_body_controller.hpp"

namespace {

using namespace mft;

struct WbcSequence {
  model::RobotDescription robot;
  model::MftPolytope polytope;
  wbc::WbcConfig config;
  std::vector<model::RobotStateEstimate> states;
  std::vector<wbc::WbcReference> refs;
};

model::VectorQ configuration(const model::RobotDescription& r, const Eigen::Vector3d& base, const Eigen::Vector2d& rf,
                             const Eigen::Vector2d& lf) {
  return model::closedLoopConfiguration(r, base, rf, lf);
}

const WbcSequence& sequence() {
  static const WbcSequence seq = [] {
    WbcSequence s;
    const std::string dir = MFT_CONFIG_DIR;
    s.robot = model::loadRobotDescription(dir + "/robot.yaml");
    s.polytope = model::loadMftPolytope(dir + "/mft_space.yaml", s.robot);
    s.config = wbc::loadWbcConfig(dir + "/wbc.yaml");
    const model::PlanarModel m = model::buildBipedModel(s.robot);
    model::ModelData data;
    const int n = 2000;
    for (int k = 0; k < n; ++k) {
      const double t = 0.001 * k;
      // Pose and its time derivative (central differences keep the velocity on the loop closure).
      auto pose = [&](double tt, Eigen::Vector3d* base, Eigen::Vector2d* rf, Eigen::Vector2d* lf) {
        *base = {0.02 * std::sin(3.0 * tt), 0.415 + 0.025 * std::sin(5.0 * tt), 0.04 * std::sin(4.0 * tt)};
        *rf = {0.04 + 0.05 * std::sin(6.0 * tt), -0.415 - 0.025 * std::sin(5.0 * tt) + 0.02 * std::cos(7.0 * tt)};
        *lf = {-0.04 - 0.05 * std::sin(6.0 * tt + 1.0), -0.415 - 0.025 * std::sin(5.0 * tt) + 0.03 * std::sin(8.0 * tt)};
      };
      Eigen::Vector3d b0, bp, bm;
      Eigen::Vector2d r0, rp, rm, l0, lp, lm;
      const double h = 1e-6;
      pose(t, &b0, &r0, &l0);
      pose(t + h, &bp, &rp, &lp);
      pose(t - h, &bm, &rm, &lm);
      model::RobotStateEstimate st;
      st.tick = static_cast<std::uint64_t>(k);
      st.q = configuration(s.robot, b0, r0, l0);
      st.qd = (configuration(s.robot, bp, rp, lp) - configuration(s.robot, bm, rm, lm)) / (2 * h);
      const int phase = (k / 100) % 3;  // 0 double support, 1 right stance, 2 left stance
      st.contact = {phase != 2, phase != 1};
      model::updateModel(m, st.q, st.qd, &data);
      wbc::WbcReference ref;
      ref.tick = st.tick;
      ref.foot_in_stance = st.contact;
      ref.base_z.pos = 0.40;
      ref.base_pitch.pos = 0.0;
      ref.foot_pos = data.foot_pos;
      for (int leg = 0; leg < 2; ++leg)
        if (!ref.foot_in_stance[leg]) {
          ref.foot_pos[2 * leg + 1] += 0.01;  // lift the swing foot
          ref.foot_vel[2 * leg] = 0.3;
        }
      s.states.push_back(st);
      s.refs.push_back(ref);
    }
    return s;
  }();
  return seq;
}

void runTicks(benchmark::State& state, wbc::WbcVariant variant) {
  const WbcSequence& seq = sequence();
  wbc::WbcConfig config = seq.config;
  config.variant = variant;
  wbc::WholeBodyController controller(seq.robot, config, &seq.polytope);
  wbc::WbcDiagnostics diag;
  bench::LatencyRecorder recorder;
  // Per-state minimum over the passes (docs/reference/qp.md#measuring-solve-time): its maximum is the worst tick without the
  // machine's interference (timer interrupts, other processes), which dominates max_us on a shared host.
  std::vector<double> min_per_state(seq.states.size(), 1e300);
  double solve_sum = 0.0, solve_max = 0.0, iterations = 0.0;
  long ticks = 0, failures = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == seq.states.size()) k = 0;
    model::ActuatorCommand cmd;
    recorder.time([&] { cmd = controller.update(seq.states[k], seq.refs[k], &diag); });
    min_per_state[k] = std::min(min_per_state[k], diag.tick_time_us);
    benchmark::DoNotOptimize(cmd.tau.data());
    failures += diag.status == qp::QpStatus::Optimal ? 0 : 1;
    solve_sum += diag.solve_time_us;
    solve_max = std::max(solve_max, diag.solve_time_us);
    iterations += diag.iterations;
    ++ticks;
    ++k;
  }
  recorder.report(state);
  if (ticks >= static_cast<long>(3 * seq.states.size()))
    state.counters["max_min3_us"] = *std::max_element(min_per_state.begin(), min_per_state.end());
  if (ticks > 0) {
    state.counters["qp_mean_us"] = solve_sum / static_cast<double>(ticks);
    state.counters["qp_max_us"] = solve_max;
    state.counters["qp_iter_mean"] = iterations / static_cast<double>(ticks);
  }
  state.counters["failures"] = static_cast<double>(failures);
  state.counters["safety_events"] = static_cast<double>(controller.safety().counters().events);
}

void BM_WbcTickMft(benchmark::State& state) { runTicks(state, wbc::WbcVariant::Mft); }
void BM_WbcTickSa(benchmark::State& state) { runTicks(state, wbc::WbcVariant::Sa); }
void BM_WbcTickNone(benchmark::State& state) { runTicks(state, wbc::WbcVariant::None); }

}  // namespace

BENCHMARK(BM_WbcTickMft)->Iterations(20000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WbcTickSa)->Iterations(20000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WbcTickNone)->Iterations(20000)->Unit(benchmark::kMicrosecond);
