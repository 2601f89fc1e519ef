#pragma once
// The hardware boundary as plain data: what the robot (or the simulator) measures, what the estimator
// reports and what the controller commands. Services copy these to and from DDS messages; libraries and
// tests use them directly (a mock of the hardware is just code that fills SensorReadings).
#include <array>
#include <cstdint>

#include "model/coordinates.hpp"

namespace mft::model {

struct SensorReadings {
  std::uint64_t tick = 0;      // control step number (the simulator's clock)
  double time_s = 0.0;         // simulated time of the measurement
  std::array<double, kNa> actuated_pos{}, actuated_vel{};   // encoders at [q4, q6, q8, q10], unwrapped
  std::array<double, kNa> passive_pos{}, passive_vel{};     // encoders at [q5, q7, q9, q11], unwrapped
  std::array<double, kNa> sea_torque{};                     // measured SEA output torques [N m]
  double gyro_pitch_rate = 0.0;                             // torso IMU, body frame, CCW rate [rad/s]
  std::array<double, 2> accel{};                            // torso IMU specific force [x, z] body frame [m/s^2]
  std::array<bool, kNumLegs> contact{};                     // foot switches [right, left]
};

// The estimator's output: the full generalized state and contact flags.
struct RobotStateEstimate {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  VectorQ q = VectorQ::Zero();
  VectorQ qd = VectorQ::Zero();
  std::array<bool, kNumLegs> contact{};
};

enum class CommandMode : std::uint8_t { Normal = 0, Damping = 1 };

struct ActuatorCommand {
  std::uint64_t tick = 0;      // the tick this command answers
  VectorA tau = VectorA::Zero();  // [q4, q6, q8, q10] torques [N m]
  CommandMode mode = CommandMode::Normal;
};

// Ground truth from the simulator (tests, recording, estimator bypass).
struct GroundTruthState {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  VectorQ q = VectorQ::Zero();
  VectorQ qd = VectorQ::Zero();
  VectorC contact_force = VectorC::Zero();  // ground on foot, world [fx, fz] right then left
  std::array<double, kNumLegs> lti{};       // local transmission index of each leg
};

}  // namespace mft::model
