#include "services/record/rawlog_format.hpp"

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "model/config/live_tuning.hpp"

namespace mft::rawlog {

using mrpt::obs::CObservationIMU;
using mrpt::obs::CObservationRawDAQ;

namespace {

constexpr std::int64_t kFiletimeUnixOffset100ns = 116444736000000000LL;  // 1601-01-01 -> 1970-01-01

const char* const kTopicNames[kNumTopics] = {"GroundTruth",  "SensorData",     "RobotState",      "Reference",
                                             "JointCommand", "WbcDiagnostics", "OperatorCommand", "Disturbance",
                                             "ConfigChange"};

std::vector<std::string> withTick(std::vector<std::string> cols) {
  cols.insert(cols.begin(), "tick");
  return cols;
}
std::vector<std::string> unitsWithTick(std::vector<std::string> u) {
  u.insert(u.begin(), "-");
  return u;
}
std::vector<std::string> repeat(const std::string& u, std::size_t n) { return std::vector<std::string>(n, u); }

const std::vector<std::string> kJoints = {"q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const std::vector<std::string> kJointsDot = {"qd4", "qd5", "qd6", "qd7", "qd8", "qd9", "qd10", "qd11"};
const std::vector<std::string> kQ = {"x", "z", "pitch", "q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const std::vector<std::string> kQd = {"xd", "zd", "pitchd", "qd4", "qd5", "qd6", "qd7", "qd8", "qd9", "qd10", "qd11"};
const std::vector<std::string> kQUnits = {"m", "m", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad"};
const std::vector<std::string> kQdUnits = {"m/s", "m/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s",
                                           "rad/s", "rad/s", "rad/s"};

std::vector<LabelSpec> makeLabels() {
  std::vector<LabelSpec> l;
  // GroundTruth
  l.push_back({"gt_q", Topic::GroundTruth, LabelClass::RawDaq, withTick(kQ), unitsWithTick(kQUnits),
               "simulator ground truth q = [x, z, pitch, q4..q11]"});
  l.push_back({"gt_qd", Topic::GroundTruth, LabelClass::RawDaq, withTick(kQd), unitsWithTick(kQdUnits),
               "simulator ground truth qd"});
  l.push_back({"contact_force", Topic::GroundTruth, LabelClass::RawDaq, withTick({"fx_right", "fz_right", "fx_left", "fz_left"}),
               unitsWithTick(repeat("N", 4)), "ground on foot, world frame"});
  l.push_back({"leg_lti", Topic::GroundTruth, LabelClass::RawDaq, withTick({"lti_right", "lti_left"}),
               unitsWithTick(repeat("-", 2)), "local transmission index of each leg (ground truth)"});
  // SensorData
  l.push_back({"joint_q", Topic::SensorData, LabelClass::RawDaq, withTick(kJoints), unitsWithTick(repeat("rad", 8)),
               "encoder positions in joint order (actuated q4 q6 q8 q10, passive q5 q7 q9 q11), unwrapped"});
  l.push_back({"joint_qd", Topic::SensorData, LabelClass::RawDaq, withTick(kJointsDot), unitsWithTick(repeat("rad/s", 8)),
               "encoder velocities in joint order"});
  l.push_back({"joint_tau_meas", Topic::SensorData, LabelClass::RawDaq, withTick({"tau_q4", "tau_q6", "tau_q8", "tau_q10"}),
               unitsWithTick(repeat("N m", 4)), "measured SEA output torques of the actuated joints"});
  l.push_back({"imu", Topic::SensorData, LabelClass::Imu, {"IMU_WY", "IMU_X_ACC", "IMU_Z_ACC"},
               {"rad/s", "m/s^2", "m/s^2"},
               "torso IMU, body frame x forward y left z up: IMU_WY = -gyro_pitch_rate (pitch is CCW about -y), "
               "IMU_X_ACC/IMU_Z_ACC = specific force [x, z]"});
  l.push_back({"foot_switch", Topic::SensorData, LabelClass::RawDaq, withTick({"right", "left"}),
               unitsWithTick(repeat("0/1", 2)), "foot contact switches"});
  // RobotState
  l.push_back({"est_q", Topic::RobotState, LabelClass::RawDaq, withTick(kQ), unitsWithTick(kQUnits),
               "estimated q (the controller's input, exact)"});
  l.push_back({"est_qd", Topic::RobotState, LabelClass::RawDaq, withTick(kQd), unitsWithTick(kQdUnits), "estimated qd"});
  l.push_back({"est_contact", Topic::RobotState, LabelClass::RawDaq, withTick({"right", "left"}),
               unitsWithTick(repeat("0/1", 2)), "estimated contact flags"});
  l.push_back({"base_est", Topic::RobotState, LabelClass::Imu,
               {"IMU_X", "IMU_Z", "IMU_PITCH", "IMU_X_VEL", "IMU_Z_VEL", "IMU_WY", "IMU_ORI_QUAT_W", "IMU_ORI_QUAT_Y"},
               {"m", "m", "rad", "m/s", "m/s", "rad/s", "-", "-"},
               "derived view of est_q/est_qd as a virtual INS for MRPT tools (MRPT pitch = -pitch, IMU_WY = -pitchd, "
               "quaternion of the rotation about y by -pitch); est_q/est_qd hold the exact values"});
  // Reference
  l.push_back({"plan_ref", Topic::Reference, LabelClass::RawDaq,
               withTick({"step_index", "phase", "stance_leg", "in_stance_right", "in_stance_left", "base_z", "base_zd",
                         "base_zdd", "pitch", "pitchd", "pitchdd", "foot_x_right", "foot_z_right", "foot_x_left",
                         "foot_z_left", "foot_vx_right", "foot_vz_right", "foot_vx_left", "foot_vz_left",
                         "foot_ax_right", "foot_az_right", "foot_ax_left", "foot_az_left", "base_x", "base_xd",
                         "base_xdd", "hold_base_x"}),
               unitsWithTick({"-", "-", "-", "0/1", "0/1", "m", "m/s", "m/s^2", "rad", "rad/s", "rad/s^2", "m", "m", "m",
                              "m", "m/s", "m/s", "m/s", "m/s", "m/s^2", "m/s^2", "m/s^2", "m/s^2", "m", "m/s", "m/s^2",
                              "0/1"}),
               "planner reference (stance_leg 0 right, 1 left, -1 double support)"});
  // JointCommand
  l.push_back({"joint_tau_cmd", Topic::JointCommand, LabelClass::RawDaq,
               withTick({"seq", "tau_q4", "tau_q6", "tau_q8", "tau_q10", "mode"}),
               unitsWithTick({"-", "N m", "N m", "N m", "N m", "-"}), "commanded torques (mode 0 normal, 1 damping)"});
  // WbcDiagnostics
  l.push_back({"wbc_diag", Topic::WbcDiagnostics, LabelClass::RawDaq,
               withTick({"solve_time_us", "tick_time_us", "iterations", "status", "active_constraints", "slack_norm",
                         "err_base_z", "err_base_pitch", "err_foot_x_right", "err_foot_z_right", "err_foot_x_left",
                         "err_foot_z_left", "lti_right", "lti_left", "raci_right", "raci_left", "safety_events",
                         "holding", "damping"}),
               unitsWithTick({"us", "us", "-", "-", "-", "rad", "m", "rad", "m", "m", "m", "m", "-", "-", "N/sqrt(kg)",
                              "N/sqrt(kg)", "-", "0/1", "0/1"}),
               "WBC diagnostics (status 0 = optimal)"});
  // Events: channel 0 is the message's seq; stamped with the newest simulator time seen on arrival.
  l.push_back({"operator_cmd", Topic::OperatorCommand, LabelClass::RawDaq, {"seq", "z_cmd", "v_cmd", "mode"},
               {"-", "m", "m/s", "-"}, "operator command (mode 0 stand, 1 step in place, 2 walk)"});
  l.push_back({"disturbance", Topic::Disturbance, LabelClass::RawDaq, {"seq", "impulse_Ns", "trigger", "time_s", "leg"},
               {"-", "N s", "-", "s", "-"}, "push request (trigger 0 at time, 1 at next lift-off of leg)"});
  // Appended after schema 1's first labels: a reader that predates it ignores the label (counted as unknown).
  l.push_back({"config_change", Topic::ConfigChange, LabelClass::RawDaq,
               {"seq", "applied", "target", "key", "at_s", "tick", "count", "value_0", "value_1"},
               {"-", "0/1", "-", "-", "s", "-", "-", "-", "-"},
               "live tuning (mft-cmd --set): a request (applied 0) or a change in force from tick (applied 1); target "
               "0 wbc.yaml, 1 planner.yaml; key = index in model/config/live_tuning.cpp tunableKeys() (-1: not "
               "tunable); value_0/value_1 the value as loaded (count of them), requests hold none"});
  return l;
}

template <std::size_t N>
void put(double*& p, const std::array<double, N>& a) {
  for (double v : a) *p++ = v;
}
template <std::size_t N>
void get(const double*& p, std::array<double, N>& a) {
  for (double& v : a) v = *p++;
}
double b2d(bool b) { return b ? 1.0 : 0.0; }
bool d2b(double d) { return d != 0.0; }
std::uint64_t d2u(double d) { return static_cast<std::uint64_t>(d); }

// RawDAQ channels of label `li` from message `m` (the caller sized `out` to the column count).
void toChannels(const Message& m, const std::string& label, double* p) {
  switch (topicOf(m)) {
    case Topic::GroundTruth: {
      const auto& g = std::get<msg::GroundTruth>(m);
      *p++ = static_cast<double>(g.tick());
      if (label == "gt_q") put(p, g.q());
      else if (label == "gt_qd") put(p, g.qd());
      else if (label == "contact_force") put(p, g.contact_force());
      else put(p, g.lti());
      break;
    }
    case Topic::SensorData: {
      const auto& s = std::get<msg::SensorData>(m);
      *p++ = static_cast<double>(s.tick());
      if (label == "joint_q" || label == "joint_qd") {
        const auto& a = label == "joint_q" ? s.actuated_pos() : s.actuated_vel();
        const auto& b = label == "joint_q" ? s.passive_pos() : s.passive_vel();
        for (std::size_t i = 0; i < 4; ++i) {
          *p++ = a[i];
          *p++ = b[i];
        }
      } else if (label == "joint_tau_meas") {
        put(p, s.sea_torque());
      } else {  // foot_switch
        *p++ = b2d(s.contact()[0]);
        *p++ = b2d(s.contact()[1]);
      }
      break;
    }
    case Topic::RobotState: {
      const auto& r = std::get<msg::RobotState>(m);
      *p++ = static_cast<double>(r.tick());
      if (label == "est_q") put(p, r.q());
      else if (label == "est_qd") put(p, r.qd());
      else {
        *p++ = b2d(r.contact()[0]);
        *p++ = b2d(r.contact()[1]);
      }
      break;
    }
    case Topic::Reference: {
      const auto& r = std::get<msg::Reference>(m);
      *p++ = static_cast<double>(r.tick());
      *p++ = static_cast<double>(r.step_index());
      *p++ = r.phase();
      *p++ = static_cast<double>(r.stance_leg());
      *p++ = b2d(r.foot_in_stance()[0]);
      *p++ = b2d(r.foot_in_stance()[1]);
      put(p, r.base_z());
      put(p, r.base_pitch());
      put(p, r.foot_pos());
      put(p, r.foot_vel());
      put(p, r.foot_acc());
      put(p, r.base_x());
      *p++ = b2d(r.hold_base_x());
      break;
    }
    case Topic::JointCommand: {
      const auto& c = std::get<msg::JointCommand>(m);
      *p++ = static_cast<double>(c.tick());
      *p++ = static_cast<double>(c.seq());
      put(p, c.tau());
      *p++ = static_cast<double>(c.mode());
      break;
    }
    case Topic::WbcDiagnostics: {
      const auto& d = std::get<msg::WbcDiagnostics>(m);
      *p++ = static_cast<double>(d.tick());
      *p++ = d.solve_time_us();
      *p++ = d.tick_time_us();
      *p++ = d.iterations();
      *p++ = d.status();
      *p++ = d.active_constraints();
      *p++ = d.slack_norm();
      put(p, d.task_error());
      put(p, d.lti());
      put(p, d.raci());
      *p++ = static_cast<double>(d.safety_events());
      *p++ = b2d(d.holding());
      *p++ = b2d(d.damping());
      break;
    }
    case Topic::OperatorCommand: {
      const auto& o = std::get<msg::OperatorCommand>(m);
      *p++ = static_cast<double>(o.seq());
      *p++ = o.z_cmd();
      *p++ = o.v_cmd();
      *p++ = o.mode();
      break;
    }
    case Topic::Disturbance: {
      const auto& d = std::get<msg::Disturbance>(m);
      *p++ = static_cast<double>(d.seq());
      *p++ = d.impulse();
      *p++ = d.trigger();
      *p++ = d.time_s();
      *p++ = d.leg();
      break;
    }
    case Topic::ConfigChange: {
      const auto& c = std::get<msg::ConfigChange>(m);
      const std::string key(c.key().data(), strnlen(c.key().data(), c.key().size()));
      *p++ = static_cast<double>(c.seq());
      *p++ = b2d(c.applied());
      *p++ = static_cast<double>(c.target());
      *p++ = static_cast<double>(
          config::tunableIndex(c.target() == msg::CONFIG_TARGET_PLANNER ? "planner" : "wbc", key));
      *p++ = c.at_s();
      *p++ = static_cast<double>(c.tick());
      *p++ = static_cast<double>(c.count());
      put(p, c.number());
      break;
    }
  }
}

// The inverse: fills the part of `m` that label `label` holds.
void fromChannels(const std::string& label, const double* p, Message* m) {
  switch (topicOf(*m)) {
    case Topic::GroundTruth: {
      auto& g = std::get<msg::GroundTruth>(*m);
      g.tick(d2u(*p++));
      if (label == "gt_q") get(p, g.q());
      else if (label == "gt_qd") get(p, g.qd());
      else if (label == "contact_force") get(p, g.contact_force());
      else get(p, g.lti());
      break;
    }
    case Topic::SensorData: {
      auto& s = std::get<msg::SensorData>(*m);
      s.tick(d2u(*p++));
      if (label == "joint_q" || label == "joint_qd") {
        auto& a = label == "joint_q" ? s.actuated_pos() : s.actuated_vel();
        auto& b = label == "joint_q" ? s.passive_pos() : s.passive_vel();
        for (std::size_t i = 0; i < 4; ++i) {
          a[i] = *p++;
          b[i] = *p++;
        }
      } else if (label == "joint_tau_meas") {
        get(p, s.sea_torque());
      } else {
        s.contact()[0] = d2b(*p++);
        s.contact()[1] = d2b(*p++);
      }
      break;
    }
    case Topic::RobotState: {
      auto& r = std::get<msg::RobotState>(*m);
      r.tick(d2u(*p++));
      if (label == "est_q") get(p, r.q());
      else if (label == "est_qd") get(p, r.qd());
      else {
        r.contact()[0] = d2b(*p++);
        r.contact()[1] = d2b(*p++);
      }
      break;
    }
    case Topic::Reference: {
      auto& r = std::get<msg::Reference>(*m);
      r.tick(d2u(*p++));
      r.step_index(d2u(*p++));
      r.phase(*p++);
      r.stance_leg(static_cast<std::int16_t>(*p++));
      r.foot_in_stance()[0] = d2b(*p++);
      r.foot_in_stance()[1] = d2b(*p++);
      get(p, r.base_z());
      get(p, r.base_pitch());
      get(p, r.foot_pos());
      get(p, r.foot_vel());
      get(p, r.foot_acc());
      get(p, r.base_x());
      r.hold_base_x(d2b(*p++));
      break;
    }
    case Topic::JointCommand: {
      auto& c = std::get<msg::JointCommand>(*m);
      c.tick(d2u(*p++));
      c.seq(d2u(*p++));
      get(p, c.tau());
      c.mode(static_cast<std::uint8_t>(*p++));
      break;
    }
    case Topic::WbcDiagnostics: {
      auto& d = std::get<msg::WbcDiagnostics>(*m);
      d.tick(d2u(*p++));
      d.solve_time_us(*p++);
      d.tick_time_us(*p++);
      d.iterations(static_cast<std::int32_t>(*p++));
      d.status(static_cast<std::int32_t>(*p++));
      d.active_constraints(static_cast<std::int32_t>(*p++));
      d.slack_norm(*p++);
      get(p, d.task_error());
      get(p, d.lti());
      get(p, d.raci());
      d.safety_events(d2u(*p++));
      d.holding(d2b(*p++));
      d.damping(d2b(*p++));
      break;
    }
    case Topic::OperatorCommand: {
      auto& o = std::get<msg::OperatorCommand>(*m);
      o.seq(d2u(*p++));
      o.z_cmd(*p++);
      o.v_cmd(*p++);
      o.mode(static_cast<std::uint8_t>(*p++));
      break;
    }
    case Topic::Disturbance: {
      auto& d = std::get<msg::Disturbance>(*m);
      d.seq(d2u(*p++));
      d.impulse(*p++);
      d.trigger(static_cast<std::uint8_t>(*p++));
      d.time_s(*p++);
      d.leg(static_cast<std::int16_t>(*p++));
      break;
    }
    case Topic::ConfigChange: {
      auto& c = std::get<msg::ConfigChange>(*m);
      c.seq(d2u(*p++));
      c.applied(d2b(*p++));
      c.target(static_cast<std::uint8_t>(*p++));
      const double key = *p++;
      const auto& keys = config::tunableKeys();
      c.key().fill('\0');
      if (key >= 0.0 && key < static_cast<double>(keys.size()))
        std::snprintf(c.key().data(), c.key().size(), "%s", keys[static_cast<std::size_t>(key)].key);
      c.at_s(*p++);
      c.tick(d2u(*p++));
      c.count(static_cast<std::uint8_t>(*p++));
      get(p, c.number());
      const std::string value = config::formatNumbers(c.number().data(), std::min<std::size_t>(c.count(), 2));
      c.value().fill('\0');
      if (c.count() > 0) std::snprintf(c.value().data(), c.value().size(), "%s", value.c_str());
      break;
    }
  }
}

Message emptyMessage(Topic t) {
  switch (t) {
    case Topic::GroundTruth: return msg::GroundTruth();
    case Topic::SensorData: return msg::SensorData();
    case Topic::RobotState: return msg::RobotState();
    case Topic::Reference: return msg::Reference();
    case Topic::JointCommand: return msg::JointCommand();
    case Topic::WbcDiagnostics: return msg::WbcDiagnostics();
    case Topic::OperatorCommand: return msg::OperatorCommand();
    case Topic::Disturbance: return msg::Disturbance();
    case Topic::ConfigChange: return msg::ConfigChange();
  }
  return msg::GroundTruth();
}

void setStamp(Message* m, std::uint64_t stamp_ns) {
  std::visit(
      [stamp_ns](auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (!std::is_same_v<T, msg::OperatorCommand> && !std::is_same_v<T, msg::Disturbance> &&
                      !std::is_same_v<T, msg::ConfigChange>)
          x.stamp_ns(stamp_ns);
      },
      *m);
}

}  // namespace

const char* topicName(Topic t) { return kTopicNames[static_cast<std::size_t>(t)]; }

bool parseTopic(const std::string& name, Topic* out) {
  for (std::size_t i = 0; i < kNumTopics; ++i)
    if (name == kTopicNames[i]) {
      *out = static_cast<Topic>(i);
      return true;
    }
  return false;
}

std::uint64_t tickOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, msg::OperatorCommand> || std::is_same_v<T, msg::Disturbance> ||
                      std::is_same_v<T, msg::ConfigChange>)
          return x.seq();
        else return x.tick();
      },
      m);
}

std::uint64_t stampOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, msg::OperatorCommand> || std::is_same_v<T, msg::Disturbance> ||
                      std::is_same_v<T, msg::ConfigChange>)
          return 0;
        else return x.stamp_ns();
      },
      m);
}

const std::vector<LabelSpec>& labels() {
  static const std::vector<LabelSpec> l = makeLabels();
  return l;
}

int labelIndex(const std::string& label) {
  const auto& l = labels();
  for (std::size_t i = 0; i < l.size(); ++i)
    if (l[i].label == label) return static_cast<int>(i);
  return -1;
}

const std::vector<int>& topicLabels(Topic t) {
  static const auto table = [] {
    std::array<std::vector<int>, kNumTopics> a;
    const auto& l = labels();
    for (std::size_t i = 0; i < l.size(); ++i) a[static_cast<std::size_t>(l[i].topic)].push_back(static_cast<int>(i));
    return a;
  }();
  return table[static_cast<std::size_t>(t)];
}

mrpt::Clock::time_point toMrptTime(std::int64_t unix_ns) {
  return mrpt::Clock::time_point(mrpt::Clock::duration(unix_ns / 100 + kFiletimeUnixOffset100ns));
}
std::int64_t fromMrptTime(mrpt::Clock::time_point t) {
  return (static_cast<std::int64_t>(t.time_since_epoch().count()) - kFiletimeUnixOffset100ns) * 100;
}

ObservationEncoder::ObservationEncoder() {
  for (const auto& spec : labels()) {
    if (spec.cls == LabelClass::RawDaq) {
      auto o = CObservationRawDAQ::Create();
      o->AIN_double.assign(spec.columns.size(), 0.0);
      o->AIN_channel_count = static_cast<std::uint16_t>(spec.columns.size());
      o->AIN_interleaved = true;
      o->sample_rate = hasTick(spec.topic) ? 1000.0 : 0.0;
      o->sensorLabel = spec.label;
      obs_.push_back(o);
    } else {
      auto o = CObservationIMU::Create();
      o->sensorLabel = spec.label;
      obs_.push_back(o);
    }
  }
}

const std::vector<int>& ObservationEncoder::encode(const Message& m, std::int64_t unix_ns) {
  const auto& idx = topicLabels(topicOf(m));
  const auto t = toMrptTime(unix_ns);
  for (int li : idx) {
    const auto& spec = labels()[static_cast<std::size_t>(li)];
    auto& base = obs_[static_cast<std::size_t>(li)];
    base->timestamp = t;
    if (spec.cls == LabelClass::RawDaq) {
      auto& o = static_cast<CObservationRawDAQ&>(*base);
      toChannels(m, spec.label, o.AIN_double.data());
    } else if (spec.label == "imu") {
      auto& o = static_cast<CObservationIMU&>(*base);
      const auto& s = std::get<msg::SensorData>(m);
      o.set(mrpt::obs::IMU_WY, -s.gyro_pitch_rate());
      o.set(mrpt::obs::IMU_X_ACC, s.accel()[0]);
      o.set(mrpt::obs::IMU_Z_ACC, s.accel()[1]);
    } else {  // base_est
      auto& o = static_cast<CObservationIMU&>(*base);
      const auto& r = std::get<msg::RobotState>(m);
      const double pitch = r.q()[2];
      o.set(mrpt::obs::IMU_X, r.q()[0]);
      o.set(mrpt::obs::IMU_Y, 0.0);
      o.set(mrpt::obs::IMU_Z, r.q()[1]);
      o.set(mrpt::obs::IMU_PITCH, -pitch);
      o.set(mrpt::obs::IMU_X_VEL, r.qd()[0]);
      o.set(mrpt::obs::IMU_Z_VEL, r.qd()[1]);
      o.set(mrpt::obs::IMU_WY, -r.qd()[2]);
      o.set(mrpt::obs::IMU_PITCH_VEL_GLOBAL, -r.qd()[2]);
      o.set(mrpt::obs::IMU_ORI_QUAT_X, 0.0);
      o.set(mrpt::obs::IMU_ORI_QUAT_Y, std::sin(-pitch / 2));
      o.set(mrpt::obs::IMU_ORI_QUAT_Z, 0.0);
      o.set(mrpt::obs::IMU_ORI_QUAT_W, std::cos(-pitch / 2));
    }
  }
  return idx;
}

bool MessageAssembler::add(const mrpt::obs::CObservation& obs, Message* out, std::int64_t* unix_ns) {
  const int li = labelIndex(obs.sensorLabel);
  if (li < 0) {
    ++unknown_;
    return false;
  }
  const auto& spec = labels()[static_cast<std::size_t>(li)];
  const auto& idx = topicLabels(spec.topic);
  std::uint32_t bit = 0;
  for (std::size_t i = 0; i < idx.size(); ++i)
    if (idx[i] == li) bit = 1u << i;
  auto& p = partial_[static_cast<std::size_t>(spec.topic)];
  const std::int64_t t = fromMrptTime(obs.timestamp);
  if (!p.active || p.unix_ns != t || (p.seen & bit)) {
    if (p.active) ++incomplete_;  // a message whose labels did not all arrive (a cut file)
    p.msg = emptyMessage(spec.topic);
    p.unix_ns = t;
    p.seen = 0;
    p.active = true;
  }
  if (spec.cls == LabelClass::RawDaq) {
    const auto* o = dynamic_cast<const CObservationRawDAQ*>(&obs);
    if (!o || o->AIN_double.size() != spec.columns.size()) {
      ++unknown_;
      return false;
    }
    fromChannels(spec.label, o->AIN_double.data(), &p.msg);
  } else if (spec.label == "imu") {
    const auto* o = dynamic_cast<const CObservationIMU*>(&obs);
    if (!o) {
      ++unknown_;
      return false;
    }
    auto& s = std::get<msg::SensorData>(p.msg);
    s.gyro_pitch_rate(-o->rawMeasurements[mrpt::obs::IMU_WY]);
    s.accel()[0] = o->rawMeasurements[mrpt::obs::IMU_X_ACC];
    s.accel()[1] = o->rawMeasurements[mrpt::obs::IMU_Z_ACC];
  }  // base_est: a derived view; est_q/est_qd carry the values
  p.seen |= bit;
  if (p.seen != (1u << idx.size()) - 1u) return false;
  p.active = false;
  if (hasTick(spec.topic)) setStamp(&p.msg, static_cast<std::uint64_t>(t - time_base_ns_));
  *out = p.msg;
  *unix_ns = t;
  return true;
}

bool observationValues(const mrpt::obs::CObservation& obs, int label_index, std::vector<double>* values) {
  const auto& spec = labels()[static_cast<std::size_t>(label_index)];
  values->clear();
  if (spec.cls == LabelClass::RawDaq) {
    const auto* o = dynamic_cast<const CObservationRawDAQ*>(&obs);
    if (!o || o->AIN_double.size() != spec.columns.size()) return false;
    values->assign(o->AIN_double.begin(), o->AIN_double.end());
    return true;
  }
  const auto* o = dynamic_cast<const CObservationIMU*>(&obs);
  if (!o) return false;
  static const std::map<std::string, mrpt::obs::TIMUDataIndex> fields = {
      {"IMU_WY", mrpt::obs::IMU_WY},       {"IMU_X_ACC", mrpt::obs::IMU_X_ACC}, {"IMU_Z_ACC", mrpt::obs::IMU_Z_ACC},
      {"IMU_X", mrpt::obs::IMU_X},         {"IMU_Z", mrpt::obs::IMU_Z},         {"IMU_PITCH", mrpt::obs::IMU_PITCH},
      {"IMU_X_VEL", mrpt::obs::IMU_X_VEL}, {"IMU_Z_VEL", mrpt::obs::IMU_Z_VEL}, {"IMU_ORI_QUAT_W", mrpt::obs::IMU_ORI_QUAT_W},
      {"IMU_ORI_QUAT_Y", mrpt::obs::IMU_ORI_QUAT_Y}};
  for (const auto& c : spec.columns) values->push_back(o->rawMeasurements[fields.at(c)]);
  return true;
}

// ------------------------------------------------------------------------------------------------ metadata
std::string metadataYaml(const Metadata& m) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << kFormatName;
  e << YAML::Key << "schema_version" << YAML::Value << kSchemaVersion;
  e << YAML::Key << "created_utc" << YAML::Value << m.created_utc;
  e << YAML::Key << "mode" << YAML::Value << m.mode;
  e << YAML::Key << "domain" << YAML::Value << m.domain;
  e << YAML::Key << "scenario_file" << YAML::Value << m.scenario_file;
  e << YAML::Key << "scenario_name" << YAML::Value << m.scenario_name;
  e << YAML::Key << "controller" << YAML::Value << m.controller;
  e << YAML::Key << "robot_checksum" << YAML::Value << m.robot_checksum;
  e << YAML::Key << "profiles" << YAML::Value << YAML::Flow << m.profiles;
  e << YAML::Comment("config/profiles/ in force; config below holds the files with them applied");
  e << YAML::Key << "dds_naming" << YAML::Value << m.dds_naming;
  e << YAML::Comment("ros2: topics rt/mft/<snake_case>, types mft::msg::dds_::<Name>_ (docs/interop.md)");
  e << YAML::Key << "time_base_unix_ns" << YAML::Value << m.time_base_unix_ns;
  e << YAML::Comment("observation timestamp = time_base_unix_ns + stamp_ns of the simulator clock");
  e << YAML::Key << "piece" << YAML::Value << m.piece;
  e << YAML::Key << "labels" << YAML::Value << YAML::BeginMap;
  for (const auto& s : labels()) {
    e << YAML::Key << s.label << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "topic" << YAML::Value << topicName(s.topic);
    e << YAML::Key << "class" << YAML::Value
      << (s.cls == LabelClass::RawDaq ? "mrpt::obs::CObservationRawDAQ" : "mrpt::obs::CObservationIMU");
    e << YAML::Key << (s.cls == LabelClass::RawDaq ? "AIN_double" : "fields") << YAML::Value << YAML::Flow << s.columns;
    e << YAML::Key << "units" << YAML::Value << YAML::Flow << s.units;
    e << YAML::Key << "description" << YAML::Value << s.description;
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  e << YAML::Key << "config" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, text] : m.config) e << YAML::Key << name << YAML::Value << YAML::Literal << text;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

Metadata parseMetadata(const std::string& text) {
  Metadata m;
  m.text = text;
  YAML::Node n;
  try {
    n = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("the metadata comment is not YAML: ") + e.what());
  }
  if (!n.IsMap() || !n["format"] || n["format"].as<std::string>("") != kFormatName)
    throw std::runtime_error("the first object is a comment but not mft-rawlog metadata");
  try {
    m.format = n["format"].as<std::string>();
    m.schema_version = n["schema_version"].as<int>();
    if (m.schema_version != kSchemaVersion)
      throw std::runtime_error("schema_version " + std::to_string(m.schema_version) + " is not supported (this tool reads " +
                               std::to_string(kSchemaVersion) + ")");
    m.created_utc = n["created_utc"].as<std::string>("");
    m.mode = n["mode"].as<std::string>("");
    m.domain = n["domain"].as<int>(-1);
    m.scenario_file = n["scenario_file"].as<std::string>("");
    m.scenario_name = n["scenario_name"].as<std::string>("");
    m.controller = n["controller"].as<std::string>("");
    m.robot_checksum = n["robot_checksum"].as<std::string>("");
    if (n["profiles"] && n["profiles"].IsSequence()) m.profiles = n["profiles"].as<std::vector<std::string>>();
    m.dds_naming = n["dds_naming"].as<std::string>("plain");
    m.time_base_unix_ns = n["time_base_unix_ns"].as<std::int64_t>();
    m.piece = n["piece"].as<int>(0);
    if (n["config"] && n["config"].IsMap())
      for (const auto& kv : n["config"]) m.config[kv.first.as<std::string>()] = kv.second.as<std::string>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("bad mft-rawlog metadata: ") + e.what());
  }
  return m;
}

}  // namespace mft::rawlog
