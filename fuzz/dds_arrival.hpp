#pragma once
// The checks the stack's services make on a sample as it arrives, one overload per topic, for the DDS fuzz
// target: each returns "" when the service would act on the sample, else the reason it refuses it.
#include <cmath>
#include <cstring>
#include <string>

#include "chain/actuator_driver.hpp"
#include "chain/input_guard.hpp"
#include "common/strict_yaml.hpp"
#include "fuzz/config_files.hpp"
#include "planner/planner_config.hpp"
#include "planner/planner_tuning.hpp"
#include "services/record/rawlog_format.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"
#include "wbc/wbc_tuning.hpp"

namespace mft::fuzz {

// The estimator, planner and WBC: msg_guard's plausibility check, then the conversion to the library's types.
template <class M, class Lib>
std::string guardedInput(const M& m) {
  if (!services::validInput(m)) return "not finite or implausible";
  Lib converted;
  services::fromMsg(m, &converted);
  return "";
}
inline std::string arrivalCheck(const msg::SensorData& m) {
  return guardedInput<msg::SensorData, model::SensorReadings>(m);
}
inline std::string arrivalCheck(const msg::GroundTruth& m) {
  return guardedInput<msg::GroundTruth, model::GroundTruthState>(m);
}
inline std::string arrivalCheck(const msg::RobotState& m) {
  return guardedInput<msg::RobotState, model::RobotStateEstimate>(m);
}
inline std::string arrivalCheck(const msg::Reference& m) { return guardedInput<msg::Reference, wbc::WbcReference>(m); }

// mft-planner's operator inbox, in its order: converted, checked against the limits, then the mode and values.
inline std::string arrivalCheck(const msg::OperatorCommand& m) {
  static const planner::PlannerConfig config = planner::parsePlannerConfig(configFile("planner.yaml"), "planner.yaml");
  static const planner::CommandLimits limits = planner::commandLimits(shippedRobot(), config.command, "planner.yaml");
  planner::OperatorCommand cmd;
  services::fromMsg(m, &cmd);
  const planner::CommandResult check = planner::checkCommand(cmd, limits);
  if (!check.accepted) return check.reason;
  if (m.mode() > msg::LOCOMOTION_WALK) return "unknown locomotion mode";
  return services::validInput(m) ? "" : "not finite or implausible";
}

// mft-sim's actuator driver.
inline std::string arrivalCheck(const msg::JointCommand& m) {
  chain::ActuatorDriver driver(shippedRobot().actuator.outputPeakTorque(), 3'000'000);
  chain::RawJointCommand raw;
  raw.tick = m.tick(), raw.seq = m.seq(), raw.mode = m.mode();
  for (std::size_t i = 0; i < raw.tau.size(); ++i) raw.tau[i] = m.tau()[i];
  const chain::InputVerdict v = driver.receive(raw, 0);
  return v == chain::InputVerdict::Ok ? "" : chain::toString(v);
}

// mft-sim's pushes from the topic (the largest push an operator may send: 100 N s).
inline std::string arrivalCheck(const msg::Disturbance& m) {
  const chain::InputVerdict v = chain::checkDisturbance(m.impulse(), m.trigger(), m.time_s(), m.leg(), 100.0);
  return v == chain::InputVerdict::Ok ? "" : chain::toString(v);
}

// mft-wbc's and mft-planner's live tuning: the key and value texts (NUL-terminated or not), the time, and the
// judge: the file's strict loader with the change set.
inline std::string arrivalCheck(const msg::ConfigChange& m) {
  const std::string key(m.key().data(), strnlen(m.key().data(), m.key().size()));
  const std::string value(m.value().data(), strnlen(m.value().data(), m.value().size()));
  if (m.applied()) return "an applied record, not a request";
  if (!std::isfinite(m.at_s()) || m.at_s() < 0.0) return "the time to apply at is not a time >= 0";
  static const std::string wbc_text = configFile("wbc.yaml"), planner_text = configFile("planner.yaml");
  try {
    if (m.target() == msg::CONFIG_TARGET_WBC)
      wbc::applyWbcOverride(wbc_text, "wbc.yaml (live change)", key, value, shippedRobot());
    else if (m.target() == msg::CONFIG_TARGET_PLANNER)
      planner::applyPlannerOverride(planner_text, "planner.yaml (live change)", key, value);
    else
      return "for no service";
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

// mft-cmd reads a verdict's reason as text up to its NUL or the field's end; WbcDiagnostics and RecorderProgress
// are only recorded (and read by the simulator's recorder flow): no check.
inline std::string arrivalCheck(const msg::CommandVerdict& m) {
  static_cast<void>(std::string(m.reason().data(), strnlen(m.reason().data(), m.reason().size())));
  return "";
}
inline std::string arrivalCheck(const msg::WbcDiagnostics&) { return ""; }
inline std::string arrivalCheck(const msg::RecorderProgress&) { return ""; }

}  // namespace mft::fuzz
