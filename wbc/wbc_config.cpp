#include "wbc/wbc_config.hpp"

#include <cmath>

#include "common/strict_yaml.hpp"

namespace mft::wbc {
namespace {

using config::ConfigError;
using config::StrictNode;

PdGains1 readGains1(StrictNode& n) { return {n.nonNegative("kp"), n.nonNegative("kd")}; }

PdGains2 readGains2(StrictNode& n) {
  PdGains2 g;
  const auto kp = n.fixed<2>("kp");
  const auto kd = n.fixed<2>("kd");
  for (int i = 0; i < 2; ++i) {
    if (kp[i] < 0.0) n.fail("kp", "gains must be >= 0");
    if (kd[i] < 0.0) n.fail("kd", "gains must be >= 0");
    g.kp[i] = kp[i];
    g.kd[i] = kd[i];
  }
  return g;
}

constexpr config::EnumName<WbcVariant> kVariantNames[] = {
    {WbcVariant::Mft, "mft"}, {WbcVariant::Sa, "sa"}, {WbcVariant::None, "none"}};

WbcConfig read(StrictNode& root) {
  root.useSchema("wbc");  // every number it reads is checked against its range (config_schema.hpp)
  WbcConfig c;
  const std::string variant = root.text("variant");
  if (!parseVariant(variant, &c.variant))
    root.fail("variant", "unknown variant '" + variant + "' (expected one of: " + config::nameList(kVariantNames, ", ") + ")");
  c.horizon_settling_times = root.positive("horizon_settling_times");

  auto& w = root.child("weights");
  c.weights.base_z = w.nonNegative("base_z");
  c.weights.base_pitch = w.nonNegative("base_pitch");
  c.weights.swing_foot = w.nonNegative("swing_foot");
  c.weights.support_foot = w.nonNegative("support_foot");
  c.weights.contact_force = w.positive("contact_force");
  c.weights.contact_force_rate = w.nonNegative("contact_force_rate");
  c.weights.slack = w.positive("slack");
  c.weights.qdd_regularization = w.positive("qdd_regularization");
  c.weights.base_x = w.nonNegative("base_x");

  auto& g = root.child("gains");
  c.gains.base_z = readGains1(g.child("base_z"));
  c.gains.base_pitch = readGains1(g.child("base_pitch"));
  c.gains.swing_foot = readGains2(g.child("swing_foot"));
  c.gains.support_foot = readGains2(g.child("support_foot"));
  c.gains.base_x = readGains1(g.child("base_x"));

  auto& l = root.child("limits");
  const auto qb = l.fixed<3>("qdd_base_max");
  for (int i = 0; i < 3; ++i) {
    if (!(qb[i] > 0.0)) l.fail("qdd_base_max", "every entry must be > 0");
    c.limits.qdd_base_max[i] = qb[i];
  }
  c.limits.qdd_joint_max_radps2 = l.positive("qdd_joint_max_radps2");
  c.limits.torque_limit_fraction = l.inRange("torque_limit_fraction", 1e-6, 1.0);

  auto& ct = root.child("contact");
  c.contact.friction_fraction = ct.inRange("friction_fraction", 1e-6, 10.0);
  c.contact.normal_force_max_N = ct.positive("normal_force_max_N");

  auto& sa = root.child("sa");
  c.sa.rear_knee_rad = sa.orderedPair<model::Interval>("rear_knee_rad");
  c.sa.fore_knee_rad = sa.orderedPair<model::Interval>("fore_knee_rad");

  auto& s = root.child("safety");
  c.safety.hold_ticks = s.nonNegativeInteger("hold_ticks");
  c.safety.damping_Nms_per_rad = s.nonNegative("damping_Nms_per_rad");
  c.safety.latch_damping = s.boolean("latch_damping");

  return c;
}

}  // namespace

const char* toString(WbcVariant v) { return config::nameOf(kVariantNames, v); }

bool parseVariant(const std::string& text, WbcVariant* out) { return config::parseName(kVariantNames, text, out); }

WbcConfig loadWbcConfig(const std::string& path) { return config::loadStrictFile(path, read); }

WbcConfig parseWbcConfig(const std::string& yaml_text, const std::string& origin) {
  return config::parseStrictString(yaml_text, origin, read);
}

void validateWbcConfig(const WbcConfig& c, const model::RobotDescription& robot) {
  const std::string where = (c.source_file.empty() ? std::string("<wbc defaults>") : c.source_file) + ": ";
  auto inside = [](const model::Interval& in, const model::Interval& out) {
    return in.lo >= out.lo && in.hi <= out.hi;
  };
  if (!inside(c.sa.rear_knee_rad, robot.rear_knee_rad))
    throw ConfigError(where + "sa.rear_knee_rad: must lie inside the robot's rear knee range joint_limits.rear_knee_rad of " +
                      robot.source_file);
  if (!inside(c.sa.fore_knee_rad, robot.fore_knee_rad))
    throw ConfigError(where + "sa.fore_knee_rad: must lie inside the robot's fore knee range joint_limits.fore_knee_rad of " +
                      robot.source_file);
  if (!(robot.actuator.sea.settling_time_s > 0.0) || !(c.horizon_settling_times > 0.0))
    throw ConfigError(where + "horizon_settling_times: the horizon (times the SEA settling time) must be > 0");
  if (!(robot.actuator.outputPeakTorque() > 0.0))
    throw ConfigError(where + "limits.torque_limit_fraction: the robot's actuator output peak torque is not > 0");
  if (c.safety.hold_ticks > 100000) throw ConfigError(where + "safety.hold_ticks: unreasonably large");
}

}  // namespace mft::wbc
