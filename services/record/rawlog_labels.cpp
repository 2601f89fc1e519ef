// The labels of the rawlog: which fields of a message go to which named channels. Only names, units and the
// grouping live here; the values move through the generic writer and reader (rawlog_layout.cpp). Channels are
// the on-disk order: never reorder them without bumping kSchemaVersion. A topic without an entry here is
// recorded through a generic label named after it (every field, in IDL order).
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "common/live_tuning.hpp"
#include "services/record/rawlog_layout.hpp"

namespace mft::rawlog::layout {

namespace {

std::vector<std::string> repeat(const std::string& u, std::size_t n) { return std::vector<std::string>(n, u); }

const std::vector<std::string> kQ = {"x", "z", "pitch", "q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const std::vector<std::string> kQd = {"xd", "zd", "pitchd", "qd4", "qd5", "qd6", "qd7", "qd8", "qd9", "qd10", "qd11"};
const std::vector<std::string> kQUnits = {"m", "m", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad", "rad"};
const std::vector<std::string> kQdUnits = {"m/s", "m/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s",
                                           "rad/s", "rad/s", "rad/s"};
const Columns kTick{"tick", {"tick"}, {"-"}};

// The encoders in joint order: actuated and passive joints alternate (q4 actuated, q5 passive, ...).
std::vector<Columns> jointOrder(const char* actuated, const char* passive, const std::string& prefix,
                                const std::string& unit) {
  std::vector<Columns> g{kTick};
  for (std::uint16_t i = 0; i < 4; ++i) {
    g.push_back({actuated, {prefix + std::to_string(4 + 2 * i)}, {unit}, i});
    g.push_back({passive, {prefix + std::to_string(5 + 2 * i)}, {unit}, i});
  }
  return g;
}

Label imu(std::string label, Topic topic, std::string description, std::vector<ImuEntry> entries) {
  Label l{std::move(label), topic, LabelClass::Imu, std::move(description), {}, std::move(entries), {}, {}, 0, nullptr};
  return l;
}
ImuEntry imuField(mrpt::obs::TIMUDataIndex index, const char* column, const char* unit, Topic topic, const char* field,
                  std::uint16_t element, double sign) {
  return {index, column, unit, static_cast<std::uint16_t>(fieldIndex(topic, field)), element, sign, nullptr};
}
ImuEntry derived(mrpt::obs::TIMUDataIndex index, const char* column, const char* unit, double (*f)(const Message&)) {
  return {index, column, unit, kDerived, 0, 1.0, f};
}

const msg::RobotState& state(const Message& m) { return std::get<msg::RobotState>(m); }

// A derived view for MRPT tools, not read back (est_q/est_qd hold the values). MRPT's pitch is -pitch.
Label baseEstimate() {
  using namespace mrpt::obs;
  return imu("base_est", Topic::RobotState,
             "derived view of est_q/est_qd as a virtual INS for MRPT tools (MRPT pitch = -pitch, IMU_WY = -pitchd, "
             "quaternion of the rotation about y by -pitch); est_q/est_qd hold the exact values",
             {derived(IMU_X, "IMU_X", "m", [](const Message& m) { return state(m).q()[0]; }),
              derived(IMU_Z, "IMU_Z", "m", [](const Message& m) { return state(m).q()[1]; }),
              derived(IMU_PITCH, "IMU_PITCH", "rad", [](const Message& m) { return -state(m).q()[2]; }),
              derived(IMU_X_VEL, "IMU_X_VEL", "m/s", [](const Message& m) { return state(m).qd()[0]; }),
              derived(IMU_Z_VEL, "IMU_Z_VEL", "m/s", [](const Message& m) { return state(m).qd()[1]; }),
              derived(IMU_WY, "IMU_WY", "rad/s", [](const Message& m) { return -state(m).qd()[2]; }),
              derived(IMU_ORI_QUAT_W, "IMU_ORI_QUAT_W", "-", [](const Message& m) { return std::cos(-state(m).q()[2] / 2); }),
              derived(IMU_ORI_QUAT_Y, "IMU_ORI_QUAT_Y", "-", [](const Message& m) { return std::sin(-state(m).q()[2] / 2); }),
              derived(IMU_Y, "", "", [](const Message&) { return 0.0; }),
              derived(IMU_PITCH_VEL_GLOBAL, "", "", [](const Message& m) { return -state(m).qd()[2]; }),
              derived(IMU_ORI_QUAT_X, "", "", [](const Message&) { return 0.0; }),
              derived(IMU_ORI_QUAT_Z, "", "", [](const Message&) { return 0.0; })});
}

// ConfigChange's key channel: its index in tunableKeys() (-1: not tunable). Schema 2 also holds key and value as
// text; a schema-1 observation gets them back from that index and the numbers.
double configKeyIndex(const Message& m) {
  const auto& c = std::get<msg::ConfigChange>(m);
  const std::string key(c.key().data(), strnlen(c.key().data(), c.key().size()));
  return static_cast<double>(config::tunableIndex(c.target() == msg::CONFIG_TARGET_PLANNER ? "planner" : "wbc", key));
}
void configFromSchema1(const double* channels, Message* m) {
  auto& c = std::get<msg::ConfigChange>(*m);
  const double index = channels[3];
  const auto& keys = config::tunableKeys();
  c.key().fill('\0');
  if (index >= 0.0 && index < static_cast<double>(keys.size()))
    std::snprintf(c.key().data(), c.key().size(), "%s", keys[static_cast<std::size_t>(index)].key);
  const std::string value = config::formatNumbers(c.number().data(), std::min<std::size_t>(c.count(), 2));
  c.value().fill('\0');
  if (c.count() > 0) std::snprintf(c.value().data(), c.value().size(), "%s", value.c_str());
}

Label configChange() {
  Label l = rawDaq("config_change", Topic::ConfigChange,
                   "live tuning (mft-cmd --set): a request (applied 0) or a change in force from tick (applied 1); "
                   "target 0 wbc.yaml, 1 planner.yaml; key = index in common/live_tuning.cpp tunableKeys() (-1: "
                   "not tunable); value_0/value_1 the value as loaded (count of them), requests hold none; stamp_ns the "
                   "simulated time of tick (schema 2 on); key and value also as text (schema 2 on)",
                   {{"seq", {"seq"}, {"-"}}, {"applied", {"applied"}, {"0/1"}}, {"target", {"target"}, {"-"}},
                    {"seq", {"key"}, {"-"}}, {"at_s", {"at_s"}, {"s"}}, {"tick", {"tick"}, {"-"}},
                    {"count", {"count"}, {"-"}}, {"number", {"value_0", "value_1"}, {"-", "-"}},
                    {"stamp_ns", {"stamp_ns"}, {"ns"}}});  // appended in schema 2
  l.schema1_channels = 9;
  l.channels[3].field = kDerived;
  l.channels[3].derive = configKeyIndex;
  l.schema1 = configFromSchema1;
  return l;
}

void addSimulatorLabels(std::vector<Label>* l) {
  using mrpt::obs::IMU_WY;
  l->push_back(rawDaq("gt_q", Topic::GroundTruth, "simulator ground truth q = [x, z, pitch, q4..q11]",
                      {kTick, {"q", kQ, kQUnits}}));
  l->push_back(rawDaq("gt_qd", Topic::GroundTruth, "simulator ground truth qd", {kTick, {"qd", kQd, kQdUnits}}));
  l->push_back(rawDaq("contact_force", Topic::GroundTruth, "ground on foot, world frame",
                      {kTick, {"contact_force", {"fx_right", "fz_right", "fx_left", "fz_left"}, repeat("N", 4)}}));
  l->push_back(rawDaq("leg_lti", Topic::GroundTruth, "local transmission index of each leg (ground truth)",
                      {kTick, {"lti", {"lti_right", "lti_left"}, repeat("-", 2)}}));
  l->push_back(rawDaq("joint_q", Topic::SensorData,
                      "encoder positions in joint order (actuated q4 q6 q8 q10, passive q5 q7 q9 q11), unwrapped",
                      jointOrder("actuated_pos", "passive_pos", "q", "rad")));
  l->push_back(rawDaq("joint_qd", Topic::SensorData, "encoder velocities in joint order",
                      jointOrder("actuated_vel", "passive_vel", "qd", "rad/s")));
  l->push_back(rawDaq("joint_tau_meas", Topic::SensorData, "measured SEA output torques of the actuated joints",
                      {kTick, {"sea_torque", {"tau_q4", "tau_q6", "tau_q8", "tau_q10"}, repeat("N m", 4)}}));
  l->push_back(imu("imu", Topic::SensorData,
                   "torso IMU, body frame x forward y left z up: IMU_WY = -gyro_pitch_rate (pitch is CCW about -y), "
                   "IMU_X_ACC/IMU_Z_ACC = specific force [x, z]",
                   {imuField(IMU_WY, "IMU_WY", "rad/s", Topic::SensorData, "gyro_pitch_rate", 0, -1.0),
                    imuField(mrpt::obs::IMU_X_ACC, "IMU_X_ACC", "m/s^2", Topic::SensorData, "accel", 0, 1.0),
                    imuField(mrpt::obs::IMU_Z_ACC, "IMU_Z_ACC", "m/s^2", Topic::SensorData, "accel", 1, 1.0)}));
  l->push_back(rawDaq("foot_switch", Topic::SensorData, "foot contact switches",
                      {kTick, {"contact", {"right", "left"}, repeat("0/1", 2)}}));
}

void addControllerLabels(std::vector<Label>* l) {
  l->push_back(rawDaq("est_q", Topic::RobotState, "estimated q (the controller's input, exact)", {kTick, {"q", kQ, kQUnits}}));
  l->push_back(rawDaq("est_qd", Topic::RobotState, "estimated qd", {kTick, {"qd", kQd, kQdUnits}}));
  l->push_back(rawDaq("est_contact", Topic::RobotState, "estimated contact flags",
                      {kTick, {"contact", {"right", "left"}, repeat("0/1", 2)}}));
  l->push_back(baseEstimate());
  l->push_back(rawDaq(
      "plan_ref", Topic::Reference, "planner reference (stance_leg 0 right, 1 left, -1 double support)",
      {kTick, {"step_index", {"step_index"}, {"-"}}, {"phase", {"phase"}, {"-"}}, {"stance_leg", {"stance_leg"}, {"-"}},
       {"foot_in_stance", {"in_stance_right", "in_stance_left"}, repeat("0/1", 2)},
       {"base_z", {"base_z", "base_zd", "base_zdd"}, {"m", "m/s", "m/s^2"}},
       {"base_pitch", {"pitch", "pitchd", "pitchdd"}, {"rad", "rad/s", "rad/s^2"}},
       {"foot_pos", {"foot_x_right", "foot_z_right", "foot_x_left", "foot_z_left"}, repeat("m", 4)},
       {"foot_vel", {"foot_vx_right", "foot_vz_right", "foot_vx_left", "foot_vz_left"}, repeat("m/s", 4)},
       {"foot_acc", {"foot_ax_right", "foot_az_right", "foot_ax_left", "foot_az_left"}, repeat("m/s^2", 4)},
       {"base_x", {"base_x", "base_xd", "base_xdd"}, {"m", "m/s", "m/s^2"}}, {"hold_base_x", {"hold_base_x"}, {"0/1"}}}));
  l->push_back(rawDaq("joint_tau_cmd", Topic::JointCommand, "commanded torques (mode 0 normal, 1 damping)",
                      {kTick, {"seq", {"seq"}, {"-"}},
                       {"tau", {"tau_q4", "tau_q6", "tau_q8", "tau_q10"}, repeat("N m", 4)}, {"mode", {"mode"}, {"-"}}}));
  l->push_back(rawDaq(
      "wbc_diag", Topic::WbcDiagnostics, "WBC diagnostics (status 0 = optimal)",
      {kTick, {"solve_time_us", {"solve_time_us"}, {"us"}}, {"tick_time_us", {"tick_time_us"}, {"us"}},
       {"iterations", {"iterations"}, {"-"}}, {"status", {"status"}, {"-"}},
       {"active_constraints", {"active_constraints"}, {"-"}}, {"slack_norm", {"slack_norm"}, {"rad"}},
       {"task_error",
        {"err_base_z", "err_base_pitch", "err_foot_x_right", "err_foot_z_right", "err_foot_x_left", "err_foot_z_left"},
        {"m", "rad", "m", "m", "m", "m"}},
       {"lti", {"lti_right", "lti_left"}, repeat("-", 2)}, {"raci", {"raci_right", "raci_left"}, repeat("N/sqrt(kg)", 2)},
       {"safety_events", {"safety_events"}, {"-"}}, {"holding", {"holding"}, {"0/1"}}, {"damping", {"damping"}, {"0/1"}}}));
}

// Events: channel 0 is the message's seq; stamped with the newest simulator time seen on arrival.
void addEventLabels(std::vector<Label>* l) {
  l->push_back(rawDaq("operator_cmd", Topic::OperatorCommand, "operator command (mode 0 stand, 1 step in place, 2 walk)",
                      {{"seq", {"seq"}, {"-"}}, {"z_cmd", {"z_cmd"}, {"m"}}, {"v_cmd", {"v_cmd"}, {"m/s"}},
                       {"mode", {"mode"}, {"-"}}}));
  l->push_back(rawDaq("disturbance", Topic::Disturbance, "push request (trigger 0 at time, 1 at next lift-off of leg)",
                      {{"seq", {"seq"}, {"-"}}, {"impulse", {"impulse_Ns"}, {"N s"}}, {"trigger", {"trigger"}, {"-"}},
                       {"time_s", {"time_s"}, {"s"}}, {"leg", {"leg"}, {"-"}}}));
  l->push_back(configChange());
}

// What a generic label holds, in words (the channels are the message's fields).
std::string genericDescription(Topic t) {
  if (t == Topic::CommandVerdict)
    return "the stack's answer to a command, push or live change, matched by seq (source 0 planner, 1 simulator, "
           "2 wbc; verdict 0 rejected, 1 scheduled, 2 applied); reason as text";
  return std::string("every field of ") + topicName(t);
}

std::vector<Label> makeTable() {
  std::vector<Label> l;
  addSimulatorLabels(&l);
  addControllerLabels(&l);
  addEventLabels(&l);
  // Every other topic: its generic label (snake_case of the topic name), appended in topic order.
  std::array<bool, kNumTopics> presented{};
  for (const auto& label : l) presented[static_cast<std::size_t>(label.topic)] = true;
  for (std::size_t t = 0; t < kNumTopics; ++t)
    if (!presented[t]) {
      const auto topic = static_cast<Topic>(t);
      std::string name;
      for (const char* c = topicName(topic); *c; ++c) {
        if (std::isupper(static_cast<unsigned char>(*c)) && !name.empty()) name += '_';
        name += static_cast<char>(std::tolower(static_cast<unsigned char>(*c)));
      }
      l.push_back(generic(name, topic, genericDescription(topic)));
    }
  finish(&l);
  return l;
}

}  // namespace

const std::vector<Label>& table() {
  static const std::vector<Label> t = makeTable();
  return t;
}

}  // namespace mft::rawlog::layout
