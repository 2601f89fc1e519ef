#pragma once
// What the planner hands to the WBC each tick. Field layout mirrors the `Reference` topic (idl/mft_msgs.idl):
// [pos, vel, acc] triples for the base, world [x, z] per foot, right foot (leg 0) then left (leg 1).
#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "model/coordinates.hpp"

namespace mft::planner {

enum class LocomotionMode : std::uint8_t { Stand = 0, StepInPlace = 1, Walk = 2 };

// How the last swing ended (diagnostics; the WBC does not need it).
// Early: contact before the nominal swing end (after the minimum phase); Late: contact during the extension;
// Forced: no contact by the end of the extension, the swap happens anyway.
enum class TouchdownKind : std::uint8_t { None = 0, Early, Late, Forced };

struct FootReference {
  bool stance = true;                 // true: hold (support foot), false: track the swing trajectory
  Eigen::Vector2d pos{0, 0}, vel{0, 0}, acc{0, 0};  // world [x, z]
};

struct PlanOutput {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  std::uint64_t step_index = 0;       // number of lift-offs since the planner started
  double phase = 0.0;                 // progress of the current swing in [0, 1]; 0 in double support
  int stance_leg = -1;                // 0 right, 1 left, -1 both (double support / standing)
  bool swing_extended = false;        // the swing runs past its nominal duration (late touchdown)
  LocomotionMode mode = LocomotionMode::Stand;
  Eigen::Vector3d base_z{0, 0, 0};      // (18): [pos, vel, acc] of the base height
  Eigen::Vector3d base_pitch{0, 0, 0};  // (18): [pos, vel, acc] of the pitch (always 0)
  // Not in the paper (it leaves base x passive, stepping stabilises it): standing in double support, the base x
  // is held at the midpoint of the two stance feet. base_x is always filled; hold_base_x says when it applies.
  Eigen::Vector3d base_x{0, 0, 0};      // [pos, vel, acc] of the base (hip axis) x
  bool hold_base_x = false;             // Stand mode and both feet in stance
  std::array<FootReference, model::kNumLegs> foot{};

  // (19) diagnostics of the current swing (zero when standing).
  double target_x = 0.0;              // planned pre-impact swing-foot x
  Eigen::Vector2d predicted_com{0, 0};  // predicted pre-impact CoM [x, xdot]
  double desired_com_speed = 0.0;     // desired pre-impact CoM speed
  TouchdownKind last_touchdown = TouchdownKind::None;

  // Flattened views in the Reference topic's order, for conversion to the WBC's reference.
  model::VectorC footPos() const { return flatten(&FootReference::pos); }
  model::VectorC footVel() const { return flatten(&FootReference::vel); }
  model::VectorC footAcc() const { return flatten(&FootReference::acc); }

 private:
  model::VectorC flatten(Eigen::Vector2d FootReference::*m) const {
    model::VectorC v;
    v << (foot[0].*m), (foot[1].*m);
    return v;
  }
};

}  // namespace mft::planner
