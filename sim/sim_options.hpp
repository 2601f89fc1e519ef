#pragma once
// Simulator options (config/sim.yaml): everything about the simulation that is not a property of the robot.
// Robot constants come from the RobotDescription only; the contact section can override the description's
// contact values for studies (override_description: true).
#include <array>
#include <cstdint>
#include <string>

namespace mft::sim {

enum class LoopClosureJoint { Ball, Hinge };
// Sea: the torque loop as a 2nd-order filter on torque; SeaMotor: the physical SEA behind it (motor with
// reflected inertia, spring, torque loop; sim/sea_actuator.hpp); Ideal: the limited command reaches the joint
// at once (model checks).
enum class ActuatorModel { Sea, SeaMotor, Ideal };

struct NoiseOptions {
  bool enabled = false;
  std::uint64_t seed = 1;
  double encoder_position_std_rad = 0.0;
  double encoder_velocity_std_radps = 0.0;
  double sea_torque_std_Nm = 0.0;
  double gyro_std_radps = 0.0;
  double gyro_bias_radps = 0.0;
  double accel_std_mps2 = 0.0;
  std::array<double, 2> accel_bias_mps2{};  // body [x, z]
};

struct SimOptions {
  std::string source_file;
  double control_period_s = 0.001;  // one step(); commands are held over it (zero-order hold)
  int substeps = 1;                 // physics steps per control period

  // World.
  double erp = 0.2;
  double cfm = 1e-10;  // keep tiny: soften contacts, never the joints (docs/reference/simulation.md#stepper-erp-and-cfm)
  LoopClosureJoint loop_closure = LoopClosureJoint::Ball;
  bool fix_torso = false;  // torso held still where it is placed (boom locked): swing and actuator tests

  // Feet and contacts.
  double foot_collision_radius_m = 0.005;
  bool contact_override_description = false;
  double friction_coefficient = 0.8;  // used only with contact_override_description
  double contact_stiffness_Npm = 2e5;
  double contact_damping_Nspm = 2e3;
  int max_contacts_per_geom = 4;
  double contact_switch_threshold_N = 5.0;
  bool link_collisions = true;  // thighs, shanks and torso also touch the ground (falls)
  double link_collision_radius_m = 0.012;

  // Hard stops (hips at their limits, knees at the five-bar's singular fold / full stretch).
  double hard_stop_stiffness_Nmprad = 1e5;
  double hard_stop_damping_Nmsprad = 50.0;

  // Actuators.
  ActuatorModel actuator_model = ActuatorModel::SeaMotor;  // the physical SEA, as config/sim.yaml
  double speed_limit_band_radps = 2.0;      // drive torque fades to zero over this band below the speed limit
  double damping_mode_gain_Nmsprad = 3.0;   // CommandMode::Damping: tau = -gain * hip rate
  // SeaMotor only (J_r, k_s, w, zeta come from the robot description).
  double sea_motor_reflected_damping_Nmsprad = 0.5;  // motor + gearbox viscous friction, output side
  double sea_motor_torque_loop_period_s = 1e-4;      // drive's torque loop period (rounded down to divide the physics step)

  NoiseOptions noise;

  double physicsStep() const { return control_period_s / substeps; }
};

// Loads config/sim.yaml strictly (every key required, unknown keys rejected); throws config::ConfigError.
SimOptions loadSimOptions(const std::string& path);
SimOptions parseSimOptions(const std::string& yaml_text, const std::string& origin);

}  // namespace mft::sim
