#include "services/estimator/estimator_loop.hpp"

#include <chrono>

#include "common/json_writer.hpp"
#include "common/strict_yaml.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"

namespace mft::services {

using Clock = std::chrono::steady_clock;

estimator::EstimatorConfig EstimatorLoop::load(const ServiceContext& ctx, const CommandLine& cli) {
  try {
    return estimator::loadEstimatorConfig(ctx.configFile("estimator.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
}

// On the chain channel the simulator writes GroundTruth(k) before SensorData(k): the sensor sample takes it first,
// so the estimator is woken once per tick (with DDS, the truth comes on its own).
EstimatorLoop::EstimatorLoop(ServiceContext& ctx, const CommandLine&, const estimator::EstimatorConfig& config)
    : ctx_(ctx),
      node_(chain::withScenarioMode(config, ctx.scenario().estimator), ctx.robot()),
      writer_(ctx.writing("RobotState")),
      truth_reader_(ctx.reading("GroundTruth"),
                    [this](const msg::GroundTruth& m) { onTruth(m); }, ChainSlotReader::Delivery::Polled),
      sensor_reader_(ctx.reading("SensorData"),
                     [this](const msg::SensorData& m) { onSensors(m); }) {}

void EstimatorLoop::onSensors(const msg::SensorData& m) {
  truth_reader_.pollChannel();
  hops_.mark(0, m.tick());
  std::lock_guard<std::mutex> lock(mutex_);
  bool new_clock = false;  // a NaN would stay in the filter for good
  if (!sensors_.takeTick(join_, m, "SensorData", &new_clock)) return;
  if (new_clock) node_.restart();
  process(true);
}

void EstimatorLoop::onTruth(const msg::GroundTruth& m) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (truth_.take(join_, m, "GroundTruth")) process(false);
}

// Tick k once SensorData(k) is here, and GroundTruth(k) when the node needs it.
void EstimatorLoop::process(bool sensor_arrived) {
  if (!sensors_.have) return;
  const model::SensorReadings& sensors = sensors_.value;
  const bool paired = !node_.needsTruth() || (truth_.have && truth_.value.tick == sensors.tick);
  const auto action = join_.decide(sensors.tick, paired, sensor_arrived);
  if (action == TickJoin::Action::Resend) writer_.write(out_msg_);
  if (action != TickJoin::Action::Compute) return;
  const auto t0 = Clock::now();
  toMsg(node_.update(sensors, &truth_.value), &out_msg_);
  out_msg_.stamp_ns(toStampNs(sensors.time_s));
  update_us_.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  hops_.mark(1, sensors.tick);
  writer_.write(out_msg_);
  hops_.mark(2, sensors.tick);
  join_.answered(sensors.tick);
}

std::string EstimatorLoop::summaryJson() {
  std::lock_guard<std::mutex> lock(mutex_);
  config::JsonWriter w;
  w.beginObject().field("service", "mft-estimator").field("mode", ctx_.scenario().estimator);
  w.field("ticks", join_.ticks()).field("last_tick", join_.lastTick());
  join_.writeCounts(w);
  writeDeadlineFields(w, sensor_reader_.deadlineCounts());
  w.key("update_time_us").raw(update_us_.json());
  return w.endObject().str();
}

}  // namespace mft::services
