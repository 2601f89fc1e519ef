#include "model/robot_description.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "common/strict_yaml.hpp"

namespace mft::model {
namespace {

using config::StrictNode;

// Physical plausibility: every quantity must lie in a range that holds for any legged robot from a small
// lab biped to a human-size machine (config/robot.yaml documents each range beside its key). A value
// outside is a typo or a unit error, and would only show later as an abort inside ODE or a NaN in the
// dynamics (masses of 1e308 or 1e-300 once did exactly that).
LinkParams readLink(StrictNode& n, const char* com_key) {
  LinkParams l;
  l.length_m = n.inRange("length_m", 0.02, 2.0, "m");
  l.mass_kg = n.inRange("mass_kg", 0.01, 100.0, "kg");
  l.com_from_joint_m = n.number(com_key);
  l.inertia_kgm2 = n.inRange("inertia_kgm2", 1e-7, 10.0, "kg m^2");
  if (l.com_from_joint_m < 0.0 || l.com_from_joint_m > l.length_m)
    n.fail(com_key, "must lie on the link, in [0, length_m]");
  return l;
}

// FNV-1a over the canonical bytes of every value: stable across formatting and comments.
struct Hasher {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= c[i];
      h *= 1099511628211ull;
    }
  }
  void add(double v) {
    if (v == 0.0) v = 0.0;  // fold -0.0
    bytes(&v, sizeof v);
  }
  void add(const std::string& s) { bytes(s.data(), s.size()); }
};

std::uint64_t computeChecksum(const RobotDescription& d) {
  Hasher h;
  h.add(d.name);
  for (double v : {d.gravity_mps2, d.torso_mass_kg, d.torso_com_m[0], d.torso_com_m[1], d.torso_inertia_kgm2,
                   d.torso_size_m[0], d.torso_size_m[1], d.imu_position_m[0], d.imu_position_m[1], d.hip_spacing_m,
                   d.foot_radius_m, d.knee_hard_stop_margin_rad, d.friction_coefficient, d.contact_stiffness_Npm,
                   d.contact_damping_Nspm})
    h.add(v);
  for (const LinkParams* l : {&d.thigh, &d.shank})
    for (double v : {l->length_m, l->mass_kg, l->com_from_joint_m, l->inertia_kgm2}) h.add(v);
  for (const Interval* i : {&d.rear_hip_rad, &d.fore_hip_rad, &d.rear_knee_rad, &d.fore_knee_rad}) {
    h.add(i->lo);
    h.add(i->hi);
  }
  const ActuatorParams& a = d.actuator;
  for (double v : {a.gear_ratio, a.rotor_inertia_kgm2, a.motor_peak_torque_Nm, a.gearbox_efficiency,
                   a.output_speed_limit_radps, a.sea.spring_stiffness_Nmprad, a.sea.natural_frequency_radps,
                   a.sea.damping_ratio, a.sea.settling_time_s})
    h.add(v);
  return h.h;
}

RobotDescription read(StrictNode& root) {
  root.useSchema("robot");  // every number it reads is checked against its range (config_schema.hpp)
  RobotDescription d;
  d.name = root.text("name");
  d.gravity_mps2 = root.inRange("gravity_mps2", 1.0, 30.0, "m/s^2");

  auto& torso = root.child("torso");
  d.torso_mass_kg = torso.inRange("mass_kg", 0.5, 500.0, "kg");
  d.torso_com_m = torso.fixedInRange<2>("com_m", -1.0, 1.0, "m");
  d.torso_inertia_kgm2 = torso.inRange("inertia_kgm2", 1e-4, 100.0, "kg m^2");
  d.torso_size_m = torso.fixedInRange<2>("size_m", 0.01, 3.0, "m");
  d.imu_position_m = torso.fixedInRange<2>("imu_position_m", -1.0, 1.0, "m");

  auto& leg = root.child("leg");
  d.hip_spacing_m = leg.inRange("hip_spacing_m", 0.0, 1.0, "m");
  d.thigh = readLink(leg.child("thigh"), "com_from_hip_m");
  d.shank = readLink(leg.child("shank"), "com_from_knee_m");
  d.foot_radius_m = leg.inRange("foot_radius_m", 0.0, 0.2, "m");
  if (2.0 * d.shank.length_m <= d.hip_spacing_m)
    leg.fail("shank.length_m", "two shanks must span the hip spacing for the legs to close");

  auto& lim = root.child("joint_limits");
  d.rear_hip_rad = lim.orderedPair<Interval>("rear_hip_rad");
  d.fore_hip_rad = lim.orderedPair<Interval>("fore_hip_rad");
  d.rear_knee_rad = lim.orderedPair<Interval>("rear_knee_rad");
  d.fore_knee_rad = lim.orderedPair<Interval>("fore_knee_rad");
  if (d.rear_hip_rad.lo < -M_PI || d.rear_hip_rad.hi > M_PI)
    lim.fail("rear_hip_rad", "hip limits must lie in [-pi, pi]");
  if (d.fore_hip_rad.lo < -M_PI || d.fore_hip_rad.hi > M_PI)
    lim.fail("fore_hip_rad", "hip limits must lie in [-pi, pi]");
  if (d.rear_knee_rad.lo < 0.0 || d.rear_knee_rad.hi > M_PI + 1e-12)
    lim.fail("rear_knee_rad", "the rear knee bends backward: limits must lie in [0, pi]");
  if (d.fore_knee_rad.lo < -M_PI - 1e-12 || d.fore_knee_rad.hi > 0.0)
    lim.fail("fore_knee_rad", "the fore knee bends forward: limits must lie in [-pi, 0]");
  d.knee_hard_stop_margin_rad = lim.inRange("knee_hard_stop_margin_rad", 0.0, 0.5, "rad");

  auto& act = root.child("actuator");
  d.actuator.gear_ratio = act.inRange("gear_ratio", 1.0, 1000.0);
  d.actuator.rotor_inertia_kgm2 = act.inRange("rotor_inertia_kgm2", 1e-8, 0.1, "kg m^2");
  d.actuator.motor_peak_torque_Nm = act.inRange("motor_peak_torque_Nm", 1e-3, 1000.0, "N m");
  d.actuator.gearbox_efficiency = act.inRange("gearbox_efficiency", 0.05, 1.0);
  d.actuator.output_speed_limit_radps = act.inRange("output_speed_limit_radps", 0.1, 1000.0, "rad/s");
  auto& sea = act.child("sea");
  d.actuator.sea.spring_stiffness_Nmprad = sea.inRange("spring_stiffness_Nmprad", 1.0, 1e7, "N m/rad");
  d.actuator.sea.natural_frequency_radps = sea.inRange("natural_frequency_radps", 1.0, 1e5, "rad/s");
  d.actuator.sea.damping_ratio = sea.inRange("damping_ratio", 0.05, 10.0);
  d.actuator.sea.settling_time_s = sea.inRange("settling_time_s", 1e-4, 10.0, "s");

  auto& contact = root.child("contact");
  d.friction_coefficient = contact.inRange("friction_coefficient", 0.01, 5.0);
  d.contact_stiffness_Npm = contact.inRange("stiffness_Npm", 100.0, 1e9, "N/m");
  d.contact_damping_Nspm = contact.inRange("damping_Nspm", 0.0, 1e7, "N s/m");

  d.checksum = computeChecksum(d);
  return d;
}

}  // namespace

RobotDescription loadRobotDescription(const std::string& path) { return config::loadStrictFile(path, read); }

RobotDescription parseRobotDescription(const std::string& yaml_text, const std::string& origin) {
  return config::parseStrictString(yaml_text, origin, read);
}

std::string checksumHex(std::uint64_t checksum) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, checksum);
  return buf;
}

}  // namespace mft::model
