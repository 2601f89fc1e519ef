#pragma once
// The robot description: plain data loaded from config/robot.yaml (the only source of robot constants).
#include <array>
#include <cstdint>
#include <string>

namespace mft::model {

struct LinkParams {
  double length_m = 0.0;
  double mass_kg = 0.0;
  double com_from_joint_m = 0.0;  // distance of the CoM from the proximal joint, along the link axis
  double inertia_kgm2 = 0.0;      // about the CoM, pitch axis
};

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
  bool contains(double v) const { return v >= lo && v <= hi; }
};

struct SeaParams {
  double spring_stiffness_Nmprad = 0.0;
  double natural_frequency_radps = 0.0;
  double damping_ratio = 0.0;
  double settling_time_s = 0.0;
};

struct ActuatorParams {
  double gear_ratio = 0.0;
  double rotor_inertia_kgm2 = 0.0;
  double motor_peak_torque_Nm = 0.0;
  double gearbox_efficiency = 1.0;
  double output_speed_limit_radps = 0.0;
  SeaParams sea;
  double outputPeakTorque() const { return gear_ratio * motor_peak_torque_Nm; }
};

struct RobotDescription {
  std::string source_file;  // where it was loaded from
  std::string name;
  double gravity_mps2 = 9.81;

  // Torso (the floating base).
  double torso_mass_kg = 0.0;
  std::array<double, 2> torso_com_m{};  // [x, z] in the base frame
  double torso_inertia_kgm2 = 0.0;
  std::array<double, 2> torso_size_m{};
  std::array<double, 2> imu_position_m{};

  // Both legs share one geometry. Hips are at (-s/2, 0) (rear) and (+s/2, 0) (fore) in the base frame.
  double hip_spacing_m = 0.0;
  LinkParams thigh;
  LinkParams shank;
  double foot_radius_m = 0.0;

  Interval rear_hip_rad, fore_hip_rad, rear_knee_rad, fore_knee_rad;
  double knee_hard_stop_margin_rad = 0.0;

  ActuatorParams actuator;

  double friction_coefficient = 0.0;
  double contact_stiffness_Npm = 0.0;
  double contact_damping_Nspm = 0.0;

  // A checksum of every value above (not of comments or formatting): derived data such as the MFT
  // polytope records it and is refused for another robot.
  std::uint64_t checksum = 0;

  double legMass() const { return 2.0 * (thigh.mass_kg + shank.mass_kg); }
  double totalMass() const { return torso_mass_kg + 2.0 * legMass(); }
};

// Loads and validates a description; throws mft::config::ConfigError naming the file and key.
RobotDescription loadRobotDescription(const std::string& path);
// Same from YAML text (tests); `origin` is used in messages.
RobotDescription parseRobotDescription(const std::string& yaml_text, const std::string& origin);

// The checksum as 16 lowercase hex digits.
std::string checksumHex(std::uint64_t checksum);

}  // namespace mft::model
