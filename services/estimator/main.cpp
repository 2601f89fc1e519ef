// mft-estimator: SensorData(k) [+ GroundTruth(k)] -> floating-base state estimate -> RobotState(k).
// The filter starts from the simulator's initial pose (the robot is placed at a known standing pose); in the
// scenario's ground_truth mode it passes the simulator's truth through (to tell controller problems from
// estimator problems).
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "estimator/state_estimator.hpp"
#include "model/config/strict_yaml.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/tick_gate.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-estimator", "State estimator service: SensorData -> RobotState.");
  services::ServiceContext::declareOptions(cli);
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  services::ServiceContext ctx("mft-estimator", cli);

  estimator::EstimatorConfig config;
  try {
    config = estimator::loadEstimatorConfig(ctx.configFile("estimator.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  config.mode = ctx.scenario().estimator == "ground_truth" ? estimator::EstimatorMode::GroundTruth
                                                          : estimator::EstimatorMode::Kalman;
  estimator::StateEstimator estimator(config, ctx.robot());

  std::mutex mutex;  // the two readers' callbacks may run on different DDS threads
  model::SensorReadings sensors;
  model::GroundTruthState truth;
  bool have_sensors = false, have_truth = false, initialized = false, answered = false;
  std::uint64_t last_tick = 0, ticks = 0, refused_inputs = 0;
  services::HopTrace hops("mft-estimator", {"sensor_in", "write", "written"});
  services::TickGate gate;  // refuses a stray far tick, follows a restarted simulator (tick_gate.hpp)
  msg::RobotState out_msg;
  services::LatencyStats update_us;
  services::TopicWriter<msg::RobotState, msg::RobotStatePubSubType> writer(ctx.participant(), "RobotState",
                                                                           ctx.chainWriterProfile());
  // Answers tick k once SensorData(k) is here (and GroundTruth(k) when it is needed). Only a repeated
  // SensorData (the simulator re-sends a tick until the chain answers) gets the cached answer again: the second
  // input topic of the same tick must not double the chain's traffic.
  auto process = [&](bool sensor_arrived) {
    if (!have_sensors) return;
    if (answered && sensors.tick == last_tick) {
      if (sensor_arrived) writer.write(out_msg);
      return;
    }
    if (answered && sensors.tick < last_tick) return;
    const bool need_truth = !initialized || config.mode == estimator::EstimatorMode::GroundTruth;
    if (need_truth && !(have_truth && truth.tick == sensors.tick)) return;
    const auto t0 = Clock::now();
    if (!initialized) {
      estimator.initialize(truth.q.head<3>(), truth.qd.head<3>(), sensors);
      initialized = true;
    }
    const auto& estimate = estimator.update(sensors, need_truth ? &truth : nullptr);
    services::toMsg(estimate, &out_msg);
    out_msg.stamp_ns(services::toStampNs(sensors.time_s));
    update_us.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    hops.mark(1, sensors.tick);
    writer.write(out_msg);
    hops.mark(2, sensors.tick);
    last_tick = sensors.tick;
    gate.answered(last_tick);
    answered = true;
    ++ticks;
  };
  services::TopicReader<msg::SensorData, msg::SensorDataPubSubType> sensor_reader(
      ctx.participant(), "SensorData", ctx.chainReaderProfile(), [&](const msg::SensorData& m) {
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        if (!services::validInput(m)) {  // a NaN would stay in the filter for good
          if (refused_inputs++ == 0) std::printf("mft-estimator: refused a non-finite or implausible SensorData (tick %llu)\n", static_cast<unsigned long long>(m.tick()));
          return;
        }
        const auto decision = gate.check(m.tick());
        if (decision == services::TickGate::Decision::Refused) return;
        if (decision == services::TickGate::Decision::NewClock) {
          std::printf("mft-estimator: the simulator's clock restarted (tick %llu after %llu): re-initializing\n",
                      static_cast<unsigned long long>(m.tick()), static_cast<unsigned long long>(last_tick));
          answered = initialized = false;
        }
        services::fromMsg(m, &sensors);
        have_sensors = true;
        process(true);
      });
  services::TopicReader<msg::GroundTruth, msg::GroundTruthPubSubType> truth_reader(
      ctx.participant(), "GroundTruth", ctx.chainReaderProfile(), [&](const msg::GroundTruth& m) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!services::validInput(m)) {
          if (refused_inputs++ == 0) std::printf("mft-estimator: refused a non-finite or implausible GroundTruth (tick %llu)\n", static_cast<unsigned long long>(m.tick()));
          return;
        }
        services::fromMsg(m, &truth);
        have_truth = true;
        process(false);
      });

  services::announceReady("mft-estimator");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  char head[256];
  std::snprintf(head, sizeof head, "{\"service\": \"mft-estimator\", \"mode\": \"%s\", \"ticks\": %llu, \"last_tick\": %llu, ",
                ctx.scenario().estimator.c_str(), static_cast<unsigned long long>(ticks),
                static_cast<unsigned long long>(last_tick));
  ctx.writeSummary(std::string(head) + "\"refused_inputs\": " + std::to_string(refused_inputs) +
                   ", \"refused_ticks\": " + std::to_string(gate.refused()) + ", \"new_clocks\": " + std::to_string(gate.newClocks()) +
                   ", \"deadline_misses\": " + std::to_string(sensor_reader.requestedDeadlineMisses()) +
                   ", \"update_time_us\": " + update_us.json() + "}");
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-estimator", [&] { return toolMain(argc, argv); });
}
