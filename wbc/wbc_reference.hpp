#pragma once
// What the planner asks of the whole-body controller for one tick (mirrors the Reference topic).
// Units SI, world frame, angles CCW about -y (coordinates.hpp).
#include <array>
#include <cstdint>

#include "model/coordinates.hpp"

namespace mft::wbc {

struct Setpoint1 {  // one coordinate: position, velocity, acceleration
  double pos = 0.0;
  double vel = 0.0;
  double acc = 0.0;
};

struct WbcReference {
  std::uint64_t tick = 0;  // the tick this reference is valid for (informative)
  // Contact schedule [right, left]: a stance foot may push (0 <= f_z <= fmax) and is tracked with the support
  // foot task; a swing foot gets f_z = 0 (hence f_x = 0) and the swing foot task.
  std::array<bool, model::kNumLegs> foot_in_stance{{true, true}};
  Setpoint1 base_z;      // [m, m/s, m/s^2]
  Setpoint1 base_pitch;  // [rad, rad/s, rad/s^2]
  // Foot point references, world [x, z] of the right foot then the left: [m], [m/s], [m/s^2].
  model::VectorC foot_pos = model::VectorC::Zero();
  model::VectorC foot_vel = model::VectorC::Zero();
  model::VectorC foot_acc = model::VectorC::Zero();
  // Base x (hip axis, world) [m, m/s, m/s^2], tracked only when hold_base_x and both feet are in stance
  // (standing; not in the paper, where base x is passive).
  Setpoint1 base_x;
  bool hold_base_x = false;

  bool allFinite() const;
};

}  // namespace mft::wbc
