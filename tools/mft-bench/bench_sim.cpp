// Simulator benchmark: one 1 ms control period (Simulator::step) of the robot standing on flat ground under a
// hip PD + gravity feed-forward, contacts active, sensors and ground truth refreshed. Argument: substeps.
// Reports per-step latency (mean/p50/p99/max) and the real-time factor rtf = control period / mean step time.
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "bench_stats.hpp"
#include "model/five_bar.hpp"
#include "model/robot_description.hpp"
#include "sim/simulator.hpp"

namespace {

using namespace mft;

// Joint-space PD around the standing pose plus -J' (0, W/2) per leg (docs/reference/simulation.md#standing-with-a-joint-pd).
model::ActuatorCommand standCommand(const model::FiveBarGeometry& g, const model::VectorA& q_des, double load,
                                    const model::SensorReadings& s) {
  model::ActuatorCommand c;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    const auto r = static_cast<std::size_t>(2 * leg), f = r + 1;
    model::FiveBarPose p;
    Eigen::Vector2d ff(0.0, 0.0);
    if (model::fiveBarForward(g, s.actuated_pos[r], s.actuated_pos[f], &p) == model::FiveBarStatus::Ok)
      ff = -model::fiveBarFootJacobian(g, p).transpose() * Eigen::Vector2d(0.0, load);
    for (std::size_t i : {r, f})
      c.tau[static_cast<int>(i)] = 300.0 * (q_des[static_cast<int>(i)] - s.actuated_pos[i]) - 6.0 * s.actuated_vel[i] + ff[i - r];
  }
  return c;
}

void BM_SimControlPeriod(benchmark::State& state) {
  const auto robot = model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  auto options = sim::loadSimOptions(std::string(MFT_CONFIG_DIR) + "/sim.yaml");
  options.substeps = static_cast<int>(state.range(0));
  sim::Simulator simulator(robot, options, sim::Terrain::flat());
  sim::StandingPose pose;
  pose.foot_offset_x_m = {0.06, -0.06};
  simulator.reset(pose);
  const auto g = model::FiveBarGeometry::from(robot);
  model::VectorA q_des;
  for (int i = 0; i < model::kNa; ++i) q_des[i] = simulator.sensors().actuated_pos[static_cast<std::size_t>(i)];
  const double load = 0.5 * robot.totalMass() * robot.gravity_mps2;
  bench::LatencyRecorder latency;
  double total_us = 0.0;
  std::int64_t steps = 0;
  for (auto _ : state) {
    simulator.setCommand(standCommand(g, q_des, load, simulator.sensors()));
    const auto t0 = std::chrono::steady_clock::now();
    latency.time([&] { simulator.step(); });
    total_us += std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    ++steps;
    if (simulator.tick() >= 20000) {  // keep each stretch short and standing; reset is outside the timing
      state.PauseTiming();
      simulator.reset(pose);
      state.ResumeTiming();
    }
  }
  latency.report(state);
  state.counters["rtf"] = steps > 0 ? options.control_period_s * 1e6 / (total_us / static_cast<double>(steps)) : 0.0;
  state.counters["contacts_ok"] = simulator.sensors().contact[0] && simulator.sensors().contact[1] ? 1.0 : 0.0;
}
BENCHMARK(BM_SimControlPeriod)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond);

}  // namespace
