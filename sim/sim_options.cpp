#include "sim/sim_options.hpp"

#include "common/strict_yaml.hpp"

namespace mft::sim {
namespace {

using config::EnumName;
using config::StrictNode;

constexpr EnumName<LoopClosureJoint> kLoopClosureNames[] = {{LoopClosureJoint::Ball, "ball"},
                                                            {LoopClosureJoint::Hinge, "hinge"}};
constexpr EnumName<ActuatorModel> kActuatorModelNames[] = {{ActuatorModel::Sea, "sea"},
                                                           {ActuatorModel::SeaMotor, "sea_motor"},
                                                           {ActuatorModel::Ideal, "ideal"}};

SimOptions read(StrictNode& root) {
  root.useSchema("sim");  // every number it reads is checked against its range (config_schema.hpp)
  SimOptions o;
  o.control_period_s = root.inRange("control_period_s", 1e-6, 0.1);
  o.substeps = root.integerInRange("substeps", 1, 100);

  auto& world = root.child("world");
  o.erp = world.inRange("erp", 0.0, 1.0);
  o.cfm = world.inRange("cfm", 0.0, 1e-3);
  o.loop_closure = world.choice("loop_closure", kLoopClosureNames);
  o.fix_torso = world.boolean("fix_torso");

  auto& contact = root.child("contact");
  o.foot_collision_radius_m = contact.inRange("foot_collision_radius_m", 1e-4, 0.05);
  o.contact_override_description = contact.boolean("override_description");
  o.friction_coefficient = contact.positive("friction_coefficient");
  o.contact_stiffness_Npm = contact.positive("stiffness_Npm");
  o.contact_damping_Nspm = contact.nonNegative("damping_Nspm");
  o.max_contacts_per_geom = contact.integerInRange("max_contacts_per_geom", 1, 16);
  o.contact_switch_threshold_N = contact.nonNegative("switch_threshold_N");
  o.link_collisions = contact.boolean("link_collisions");
  o.link_collision_radius_m = contact.inRange("link_collision_radius_m", 1e-3, 0.1);

  auto& stops = root.child("hard_stops");
  o.hard_stop_stiffness_Nmprad = stops.positive("stiffness_Nmprad");
  o.hard_stop_damping_Nmsprad = stops.nonNegative("damping_Nmsprad");

  auto& act = root.child("actuators");
  o.actuator_model = act.choice("model", kActuatorModelNames);
  o.speed_limit_band_radps = act.positive("speed_limit_band_radps");
  o.damping_mode_gain_Nmsprad = act.nonNegative("damping_mode_gain_Nmsprad");
  auto& motor = act.child("sea_motor");
  o.sea_motor_reflected_damping_Nmsprad = motor.nonNegative("reflected_damping_Nmsprad");
  o.sea_motor_torque_loop_period_s = motor.inRange("torque_loop_period_s", 1e-6, 0.1);

  auto& noise = root.child("noise");
  o.noise.enabled = noise.boolean("enabled");
  o.noise.seed = static_cast<std::uint64_t>(noise.nonNegativeInteger("seed"));
  o.noise.encoder_position_std_rad = noise.nonNegative("encoder_position_std_rad");
  o.noise.encoder_velocity_std_radps = noise.nonNegative("encoder_velocity_std_radps");
  o.noise.sea_torque_std_Nm = noise.nonNegative("sea_torque_std_Nm");
  o.noise.gyro_std_radps = noise.nonNegative("gyro_std_radps");
  o.noise.gyro_bias_radps = noise.number("gyro_bias_radps");
  o.noise.accel_std_mps2 = noise.nonNegative("accel_std_mps2");
  o.noise.accel_bias_mps2 = noise.fixed<2>("accel_bias_mps2");

  return o;
}

}  // namespace

SimOptions loadSimOptions(const std::string& path) { return config::loadStrictFile(path, read); }

SimOptions parseSimOptions(const std::string& yaml_text, const std::string& origin) {
  return config::parseStrictString(yaml_text, origin, read);
}

}  // namespace mft::sim
