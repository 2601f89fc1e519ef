#include "services/record/rawlog_format.hpp"

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "common/live_tuning.hpp"

namespace mft::rawlog {

using mrpt::obs::CObservationIMU;
using mrpt::obs::CObservationRawDAQ;

namespace {

constexpr std::int64_t kFiletimeUnixOffset100ns = 116444736000000000LL;  // 1601-01-01 -> 1970-01-01

const char* const kTopicNames[kNumTopics] = {"GroundTruth",  "SensorData",     "RobotState",      "Reference",
                                             "JointCommand", "WbcDiagnostics", "OperatorCommand", "Disturbance",
                                             "ConfigChange"};

std::vector<std::string> repeat(const std::string& u, std::size_t n) { return std::vector<std::string>(n, u); }

// ---- the layout tables ----
// Each label is one table of fields; the writer, the reader and the column names (CSV export, metadata) all
// follow from it, so the three cannot disagree.

// `columns.size()` consecutive AIN_double channels of a message.
struct ChannelField {
  std::vector<std::string> columns, units;
  std::function<void(const Message&, double*)> write;
  std::function<void(const double*, Message*)> read;
};
// One CObservationIMU entry. `column` empty: stored for MRPT tools, not exported; `read` empty: derived, not
// read back.
struct ImuField {
  mrpt::obs::TIMUDataIndex index;
  std::string column, unit;
  std::function<double(const Message&)> write;
  std::function<void(double, Message*)> read;
};
struct LabelLayout {
  std::string label;
  Topic topic;
  LabelClass cls;
  std::string description;
  std::vector<ChannelField> channels;  // RawDaq
  std::vector<ImuField> imu;           // Imu
};

// An accessor of a generated message member: the value when const, a reference to it otherwise.
#define MFT_MEMBER(name) [](auto& msg) -> decltype(auto) { return msg.name(); }

// One number; stored as double, read back with a cast to the member's type (flags: != 0).
template <class M, class Access>
ChannelField scalar(const std::string& column, const std::string& unit, Access access) {
  return {{column},
          {unit},
          [access](const Message& m, double* out) { *out = static_cast<double>(access(std::get<M>(m))); },
          [access](const double* in, Message* m) {
            decltype(auto) member = access(std::get<M>(*m));
            member = static_cast<std::decay_t<decltype(member)>>(*in);
          }};
}

// A fixed-size array, element by element.
template <class M, class Access>
ChannelField array(std::vector<std::string> columns, std::vector<std::string> units, Access access) {
  using A = std::decay_t<decltype(access(std::declval<M&>()))>;
  if (columns.size() != std::tuple_size<A>::value || units.size() != columns.size())
    throw std::logic_error("rawlog layout: column count of " + columns.front() + " does not match the message");
  return {std::move(columns), std::move(units),
          [access](const Message& m, double* out) {
            for (const auto& v : access(std::get<M>(m))) *out++ = static_cast<double>(v);
          },
          [access](const double* in, Message* m) {
            for (auto& v : access(std::get<M>(*m))) v = static_cast<typename A::value_type>(*in++);
          }};
}

template <class M>
ChannelField tick() {
  return scalar<M>("tick", "-", MFT_MEMBER(tick));
}

// The encoders in joint order: actuated and passive joints alternate (q4 actuated, q5 passive, ...).
template <class Actuated, class Passive>
ChannelField jointOrder(std::vector<std::string> columns, const std::string& unit, Actuated actuated, Passive passive) {
  const auto n = columns.size();
  return {std::move(columns), repeat(unit, n),
          [actuated, passive](const Message& m, double* out) {
            const auto& s = std::get<msg::SensorData>(m);
            for (std::size_t i = 0; i < 4; ++i) {
              *out++ = actuated(s)[i];
              *out++ = passive(s)[i];
            }
          },
          [actuated, passive](const double* in, Message* m) {
            auto& s = std::get<msg::SensorData>(*m);
            for (std::size_t i = 0; i < 4; ++i) {
              actuated(s)[i] = *in++;
              passive(s)[i] = *in++;
            }
          }};
}

// ConfigChange's key, stored as its index in tunableKeys() (-1: not tunable, read back as "").
ChannelField configKey() {
  return {{"key"}, {"-"},
          [](const Message& m, double* out) {
            const auto& c = std::get<msg::ConfigChange>(m);
            const std::string key(c.key().data(), strnlen(c.key().data(), c.key().size()));
            *out = static_cast<double>(
                config::tunableIndex(c.target() == msg::CONFIG_TARGET_PLANNER ? "planner" : "wbc", key));
          },
          [](const double* in, Message* m) {
            auto& c = std::get<msg::ConfigChange>(*m);
            const auto& keys = config::tunableKeys();
            c.key().fill('\0');
            if (*in >= 0.0 && *in < static_cast<double>(keys.size()))
              std::snprintf(c.key().data(), c.key().size(), "%s", keys[static_cast<std::size_t>(*in)].key);
          }};
}

// ConfigChange's numbers; reading them also restores the value text (after `count`, which comes first).
ChannelField configValues() {
  ChannelField f = array<msg::ConfigChange>({"value_0", "value_1"}, {"-", "-"}, MFT_MEMBER(number));
  const auto read_numbers = f.read;
  f.read = [read_numbers](const double* in, Message* m) {
    read_numbers(in, m);
    auto& c = std::get<msg::ConfigChange>(*m);
    const std::string value = config::formatNumbers(c.number().data(), std::min<std::size_t>(c.count(), 2));
    c.value().fill('\0');
    if (c.count() > 0) std::snprintf(c.value().data(), c.value().size(), "%s", value.c_str());
  };
  return f;
}

LabelLayout rawDaq(std::string label, Topic topic, std::string description, std::vector<ChannelField> channels) {
  return {std::move(label), topic, LabelClass::RawDaq, std::move(description), std::move(channels), {}};
}
LabelLayout imu(std::string label, Topic topic, std::string description, std::vector<ImuField> fields) {
  return {std::move(label), topic, LabelClass::Imu, std::move(description), {}, std::move(fields)};
}

const std::vector<std::string> kJoints = {"q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const std::vector<std::string> kJointsDot = {"qd4", "qd5", "qd6", "qd7", "qd8", "qd9", "qd10", "qd11"};
const std::vector<std::string> kQ = {"x", "z", "pitch", "q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const std::vector<std::string> kQd = {"xd", "zd", "pitchd", "qd4", "qd5", "qd6", "qd7", "qd8", "qd9", "qd10", "qd11"};
const std::vector<std::string> kQUnits = {"m", "m", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad"};
const std::vector<std::string> kQdUnits = {"m/s", "m/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s",
                                           "rad/s", "rad/s", "rad/s"};

// Every label of schema 1 in writing order: channel order here is the on-disk order (never reorder without
// bumping kSchemaVersion).
std::vector<LabelLayout> makeLayouts() {
  using namespace msg;
  using mrpt::obs::TIMUDataIndex;
  const auto sensor = [](const Message& m) -> const SensorData& { return std::get<SensorData>(m); };
  const auto state = [](const Message& m) -> const RobotState& { return std::get<RobotState>(m); };
  std::vector<LabelLayout> l;
  // GroundTruth
  l.push_back(rawDaq("gt_q", Topic::GroundTruth, "simulator ground truth q = [x, z, pitch, q4..q11]",
                     {tick<GroundTruth>(), array<GroundTruth>(kQ, kQUnits, MFT_MEMBER(q))}));
  l.push_back(rawDaq("gt_qd", Topic::GroundTruth, "simulator ground truth qd",
                     {tick<GroundTruth>(), array<GroundTruth>(kQd, kQdUnits, MFT_MEMBER(qd))}));
  l.push_back(rawDaq("contact_force", Topic::GroundTruth, "ground on foot, world frame",
                     {tick<GroundTruth>(), array<GroundTruth>({"fx_right", "fz_right", "fx_left", "fz_left"},
                                                              repeat("N", 4), MFT_MEMBER(contact_force))}));
  l.push_back(rawDaq("leg_lti", Topic::GroundTruth, "local transmission index of each leg (ground truth)",
                     {tick<GroundTruth>(), array<GroundTruth>({"lti_right", "lti_left"}, repeat("-", 2), MFT_MEMBER(lti))}));
  // SensorData
  l.push_back(rawDaq("joint_q", Topic::SensorData,
                     "encoder positions in joint order (actuated q4 q6 q8 q10, passive q5 q7 q9 q11), unwrapped",
                     {tick<SensorData>(), jointOrder(kJoints, "rad", MFT_MEMBER(actuated_pos), MFT_MEMBER(passive_pos))}));
  l.push_back(rawDaq("joint_qd", Topic::SensorData, "encoder velocities in joint order",
                     {tick<SensorData>(), jointOrder(kJointsDot, "rad/s", MFT_MEMBER(actuated_vel), MFT_MEMBER(passive_vel))}));
  l.push_back(rawDaq("joint_tau_meas", Topic::SensorData, "measured SEA output torques of the actuated joints",
                     {tick<SensorData>(), array<SensorData>({"tau_q4", "tau_q6", "tau_q8", "tau_q10"}, repeat("N m", 4),
                                                            MFT_MEMBER(sea_torque))}));
  l.push_back(imu("imu", Topic::SensorData,
                  "torso IMU, body frame x forward y left z up: IMU_WY = -gyro_pitch_rate (pitch is CCW about -y), "
                  "IMU_X_ACC/IMU_Z_ACC = specific force [x, z]",
                  {{mrpt::obs::IMU_WY, "IMU_WY", "rad/s", [=](const Message& m) { return -sensor(m).gyro_pitch_rate(); },
                    [](double v, Message* m) { std::get<SensorData>(*m).gyro_pitch_rate(-v); }},
                   {mrpt::obs::IMU_X_ACC, "IMU_X_ACC", "m/s^2", [=](const Message& m) { return sensor(m).accel()[0]; },
                    [](double v, Message* m) { std::get<SensorData>(*m).accel()[0] = v; }},
                   {mrpt::obs::IMU_Z_ACC, "IMU_Z_ACC", "m/s^2", [=](const Message& m) { return sensor(m).accel()[1]; },
                    [](double v, Message* m) { std::get<SensorData>(*m).accel()[1] = v; }}}));
  l.push_back(rawDaq("foot_switch", Topic::SensorData, "foot contact switches",
                     {tick<SensorData>(), array<SensorData>({"right", "left"}, repeat("0/1", 2), MFT_MEMBER(contact))}));
  // RobotState
  l.push_back(rawDaq("est_q", Topic::RobotState, "estimated q (the controller's input, exact)",
                     {tick<RobotState>(), array<RobotState>(kQ, kQUnits, MFT_MEMBER(q))}));
  l.push_back(rawDaq("est_qd", Topic::RobotState, "estimated qd",
                     {tick<RobotState>(), array<RobotState>(kQd, kQdUnits, MFT_MEMBER(qd))}));
  l.push_back(rawDaq("est_contact", Topic::RobotState, "estimated contact flags",
                     {tick<RobotState>(), array<RobotState>({"right", "left"}, repeat("0/1", 2), MFT_MEMBER(contact))}));
  // A derived view for MRPT tools, not read back (est_q/est_qd hold the values). MRPT's pitch is -pitch.
  const auto pitch = [=](const Message& m) { return state(m).q()[2]; };
  const auto zero = [](const Message&) { return 0.0; };
  l.push_back(imu("base_est", Topic::RobotState,
                  "derived view of est_q/est_qd as a virtual INS for MRPT tools (MRPT pitch = -pitch, IMU_WY = -pitchd, "
                  "quaternion of the rotation about y by -pitch); est_q/est_qd hold the exact values",
                  {{mrpt::obs::IMU_X, "IMU_X", "m", [=](const Message& m) { return state(m).q()[0]; }, {}},
                   {mrpt::obs::IMU_Z, "IMU_Z", "m", [=](const Message& m) { return state(m).q()[1]; }, {}},
                   {mrpt::obs::IMU_PITCH, "IMU_PITCH", "rad", [=](const Message& m) { return -pitch(m); }, {}},
                   {mrpt::obs::IMU_X_VEL, "IMU_X_VEL", "m/s", [=](const Message& m) { return state(m).qd()[0]; }, {}},
                   {mrpt::obs::IMU_Z_VEL, "IMU_Z_VEL", "m/s", [=](const Message& m) { return state(m).qd()[1]; }, {}},
                   {mrpt::obs::IMU_WY, "IMU_WY", "rad/s", [=](const Message& m) { return -state(m).qd()[2]; }, {}},
                   {mrpt::obs::IMU_ORI_QUAT_W, "IMU_ORI_QUAT_W", "-",
                    [=](const Message& m) { return std::cos(-pitch(m) / 2); }, {}},
                   {mrpt::obs::IMU_ORI_QUAT_Y, "IMU_ORI_QUAT_Y", "-",
                    [=](const Message& m) { return std::sin(-pitch(m) / 2); }, {}},
                   {mrpt::obs::IMU_Y, "", "", zero, {}},
                   {mrpt::obs::IMU_PITCH_VEL_GLOBAL, "", "", [=](const Message& m) { return -state(m).qd()[2]; }, {}},
                   {mrpt::obs::IMU_ORI_QUAT_X, "", "", zero, {}},
                   {mrpt::obs::IMU_ORI_QUAT_Z, "", "", zero, {}}}));
  // Reference
  l.push_back(rawDaq(
      "plan_ref", Topic::Reference, "planner reference (stance_leg 0 right, 1 left, -1 double support)",
      {tick<Reference>(), scalar<Reference>("step_index", "-", MFT_MEMBER(step_index)),
       scalar<Reference>("phase", "-", MFT_MEMBER(phase)), scalar<Reference>("stance_leg", "-", MFT_MEMBER(stance_leg)),
       array<Reference>({"in_stance_right", "in_stance_left"}, repeat("0/1", 2), MFT_MEMBER(foot_in_stance)),
       array<Reference>({"base_z", "base_zd", "base_zdd"}, {"m", "m/s", "m/s^2"}, MFT_MEMBER(base_z)),
       array<Reference>({"pitch", "pitchd", "pitchdd"}, {"rad", "rad/s", "rad/s^2"}, MFT_MEMBER(base_pitch)),
       array<Reference>({"foot_x_right", "foot_z_right", "foot_x_left", "foot_z_left"}, repeat("m", 4), MFT_MEMBER(foot_pos)),
       array<Reference>({"foot_vx_right", "foot_vz_right", "foot_vx_left", "foot_vz_left"}, repeat("m/s", 4),
                        MFT_MEMBER(foot_vel)),
       array<Reference>({"foot_ax_right", "foot_az_right", "foot_ax_left", "foot_az_left"}, repeat("m/s^2", 4),
                        MFT_MEMBER(foot_acc)),
       array<Reference>({"base_x", "base_xd", "base_xdd"}, {"m", "m/s", "m/s^2"}, MFT_MEMBER(base_x)),
       scalar<Reference>("hold_base_x", "0/1", MFT_MEMBER(hold_base_x))}));
  // JointCommand
  l.push_back(rawDaq("joint_tau_cmd", Topic::JointCommand, "commanded torques (mode 0 normal, 1 damping)",
                     {tick<JointCommand>(), scalar<JointCommand>("seq", "-", MFT_MEMBER(seq)),
                      array<JointCommand>({"tau_q4", "tau_q6", "tau_q8", "tau_q10"}, repeat("N m", 4), MFT_MEMBER(tau)),
                      scalar<JointCommand>("mode", "-", MFT_MEMBER(mode))}));
  // WbcDiagnostics
  l.push_back(rawDaq(
      "wbc_diag", Topic::WbcDiagnostics, "WBC diagnostics (status 0 = optimal)",
      {tick<WbcDiagnostics>(), scalar<WbcDiagnostics>("solve_time_us", "us", MFT_MEMBER(solve_time_us)),
       scalar<WbcDiagnostics>("tick_time_us", "us", MFT_MEMBER(tick_time_us)),
       scalar<WbcDiagnostics>("iterations", "-", MFT_MEMBER(iterations)),
       scalar<WbcDiagnostics>("status", "-", MFT_MEMBER(status)),
       scalar<WbcDiagnostics>("active_constraints", "-", MFT_MEMBER(active_constraints)),
       scalar<WbcDiagnostics>("slack_norm", "rad", MFT_MEMBER(slack_norm)),
       array<WbcDiagnostics>({"err_base_z", "err_base_pitch", "err_foot_x_right", "err_foot_z_right", "err_foot_x_left",
                              "err_foot_z_left"},
                             {"m", "rad", "m", "m", "m", "m"}, MFT_MEMBER(task_error)),
       array<WbcDiagnostics>({"lti_right", "lti_left"}, repeat("-", 2), MFT_MEMBER(lti)),
       array<WbcDiagnostics>({"raci_right", "raci_left"}, repeat("N/sqrt(kg)", 2), MFT_MEMBER(raci)),
       scalar<WbcDiagnostics>("safety_events", "-", MFT_MEMBER(safety_events)),
       scalar<WbcDiagnostics>("holding", "0/1", MFT_MEMBER(holding)),
       scalar<WbcDiagnostics>("damping", "0/1", MFT_MEMBER(damping))}));
  // Events: channel 0 is the message's seq; stamped with the newest simulator time seen on arrival.
  l.push_back(rawDaq("operator_cmd", Topic::OperatorCommand, "operator command (mode 0 stand, 1 step in place, 2 walk)",
                     {scalar<OperatorCommand>("seq", "-", MFT_MEMBER(seq)),
                      scalar<OperatorCommand>("z_cmd", "m", MFT_MEMBER(z_cmd)),
                      scalar<OperatorCommand>("v_cmd", "m/s", MFT_MEMBER(v_cmd)),
                      scalar<OperatorCommand>("mode", "-", MFT_MEMBER(mode))}));
  l.push_back(rawDaq("disturbance", Topic::Disturbance, "push request (trigger 0 at time, 1 at next lift-off of leg)",
                     {scalar<Disturbance>("seq", "-", MFT_MEMBER(seq)),
                      scalar<Disturbance>("impulse_Ns", "N s", MFT_MEMBER(impulse)),
                      scalar<Disturbance>("trigger", "-", MFT_MEMBER(trigger)),
                      scalar<Disturbance>("time_s", "s", MFT_MEMBER(time_s)),
                      scalar<Disturbance>("leg", "-", MFT_MEMBER(leg))}));
  // Appended after schema 1's first labels: a reader that predates it ignores the label (counted as unknown).
  l.push_back(rawDaq("config_change", Topic::ConfigChange,
                     "live tuning (mft-cmd --set): a request (applied 0) or a change in force from tick (applied 1); "
                     "target 0 wbc.yaml, 1 planner.yaml; key = index in common/live_tuning.cpp tunableKeys() (-1: "
                     "not tunable); value_0/value_1 the value as loaded (count of them), requests hold none",
                     {scalar<ConfigChange>("seq", "-", MFT_MEMBER(seq)),
                      scalar<ConfigChange>("applied", "0/1", MFT_MEMBER(applied)),
                      scalar<ConfigChange>("target", "-", MFT_MEMBER(target)), configKey(),
                      scalar<ConfigChange>("at_s", "s", MFT_MEMBER(at_s)),
                      scalar<ConfigChange>("tick", "-", MFT_MEMBER(tick)),
                      scalar<ConfigChange>("count", "-", MFT_MEMBER(count)), configValues()}));
  return l;
}
#undef MFT_MEMBER

const std::vector<LabelLayout>& layouts() {
  static const std::vector<LabelLayout> l = makeLayouts();
  return l;
}

std::vector<LabelSpec> makeLabels() {
  std::vector<LabelSpec> specs;
  for (const auto& layout : layouts()) {
    LabelSpec s{layout.label, layout.topic, layout.cls, {}, {}, layout.description};
    for (const auto& f : layout.channels) {
      s.columns.insert(s.columns.end(), f.columns.begin(), f.columns.end());
      s.units.insert(s.units.end(), f.units.begin(), f.units.end());
    }
    for (const auto& f : layout.imu)
      if (!f.column.empty()) {
        s.columns.push_back(f.column);
        s.units.push_back(f.unit);
      }
    specs.push_back(std::move(s));
  }
  return specs;
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

// Events (operator commands, pushes, live changes) carry a sequence number instead of a tick, and no stamp.
template <class T>
constexpr bool kIsEvent = std::is_same_v<T, msg::OperatorCommand> || std::is_same_v<T, msg::Disturbance> ||
                          std::is_same_v<T, msg::ConfigChange>;

std::uint64_t tickOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        if constexpr (kIsEvent<std::decay_t<decltype(x)>>) return x.seq();
        else return x.tick();
      },
      m);
}

std::uint64_t stampOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        if constexpr (kIsEvent<std::decay_t<decltype(x)>>) return 0;
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
    const auto& layout = layouts()[static_cast<std::size_t>(li)];
    auto& base = obs_[static_cast<std::size_t>(li)];
    base->timestamp = t;
    if (layout.cls == LabelClass::RawDaq) {
      double* channel = static_cast<CObservationRawDAQ&>(*base).AIN_double.data();
      for (const auto& f : layout.channels) {
        f.write(m, channel);
        channel += f.columns.size();
      }
    } else {
      auto& o = static_cast<CObservationIMU&>(*base);
      for (const auto& f : layout.imu) o.set(f.index, f.write(m));
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
  const auto& layout = layouts()[static_cast<std::size_t>(li)];
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
    const double* channel = o->AIN_double.data();
    for (const auto& f : layout.channels) {
      f.read(channel, &p.msg);
      channel += f.columns.size();
    }
  } else {
    const auto* o = dynamic_cast<const CObservationIMU*>(&obs);
    if (!o) {
      ++unknown_;
      return false;
    }
    for (const auto& f : layout.imu)
      if (f.read) f.read(o->rawMeasurements[f.index], &p.msg);
  }
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
  for (const auto& f : layouts()[static_cast<std::size_t>(label_index)].imu)
    if (!f.column.empty()) values->push_back(o->rawMeasurements[f.index]);
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
