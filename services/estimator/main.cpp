// mft-estimator: the estimator stage of the chain (chain/estimator_node.hpp) as a service:
// SensorData(k) [+ GroundTruth(k)] -> RobotState(k). The filter starts from the simulator's pose at the first
// tick; in the scenario's ground_truth mode it passes the simulator's truth through.
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "chain/estimator_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"

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
  chain::EstimatorNode node(chain::withScenarioMode(config, ctx.scenario().estimator), ctx.robot());

  std::mutex mutex;  // the two readers' callbacks may run on different DDS threads
  model::SensorReadings sensors;
  model::GroundTruthState truth;
  bool have_sensors = false, have_truth = false;
  services::TickJoin join("mft-estimator");
  services::HopTrace hops("mft-estimator", {"sensor_in", "write", "written"});
  msg::RobotState out_msg;
  services::LatencyStats update_us;
  services::TopicWriter<msg::RobotState, msg::RobotStatePubSubType> writer(ctx.participant(), "RobotState",
                                                                           ctx.chainWriterProfile());
  // Tick k once SensorData(k) is here, and GroundTruth(k) when the node needs it.
  auto process = [&](bool sensor_arrived) {
    if (!have_sensors) return;
    const bool paired = !node.needsTruth() || (have_truth && truth.tick == sensors.tick);
    const auto action = join.decide(sensors.tick, paired, sensor_arrived);
    if (action == services::TickJoin::Action::Resend) writer.write(out_msg);
    if (action != services::TickJoin::Action::Compute) return;
    const auto t0 = Clock::now();
    services::toMsg(node.update(sensors, &truth), &out_msg);
    out_msg.stamp_ns(services::toStampNs(sensors.time_s));
    update_us.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    hops.mark(1, sensors.tick);
    writer.write(out_msg);
    hops.mark(2, sensors.tick);
    join.answered(sensors.tick);
  };
  // On the chain channel the simulator writes GroundTruth(k) before SensorData(k): the sensor sample takes it first,
  // so the estimator is woken once per tick (with DDS, the truth comes on its own).
  services::TopicReader<msg::GroundTruth, msg::GroundTruthPubSubType> truth_reader(
      ctx.participant(), "GroundTruth", ctx.chainReaderProfile(), [&](const msg::GroundTruth& m) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!join.accept(services::validInput(m), "GroundTruth", m.tick())) return;
        services::fromMsg(m, &truth);
        have_truth = true;
        process(false);
      }, services::ChainSlotReader::Delivery::Polled);
  services::TopicReader<msg::SensorData, msg::SensorDataPubSubType> sensor_reader(
      ctx.participant(), "SensorData", ctx.chainReaderProfile(), [&](const msg::SensorData& m) {
        truth_reader.pollChannel();
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        bool new_clock = false;  // a NaN would stay in the filter for good
        if (!join.accept(services::validInput(m), "SensorData", m.tick()) || !join.admit(m.tick(), &new_clock)) return;
        if (new_clock) node.restart();
        services::fromMsg(m, &sensors);
        have_sensors = true;
        process(true);
      });
  services::announceReady("mft-estimator");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  config::JsonWriter w;
  w.beginObject().field("service", "mft-estimator").field("mode", ctx.scenario().estimator);
  w.field("ticks", join.ticks()).field("last_tick", join.lastTick());
  join.writeCounts(w);
  services::writeDeadlineFields(w, sensor_reader.deadlineCounts());
  w.key("update_time_us").raw(update_us.json());
  ctx.writeSummary(w.endObject().str());
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-estimator", [&] { return toolMain(argc, argv); });
}
