#pragma once
// Checks of what arrives from the network before it reaches the actuators or the robot (docs/results/faults.md):
// the simulator's actuator driver refuses a joint command that is not finite, beyond the actuators' peak
// torque or of an unknown mode (a refused command counts as a missing one, so the command watchdog damps),
// and a disturbance that is not finite, beyond the largest push an operator may send, or malformed.
// Pure functions on plain values: unit-tested directly (tests/faults).
#include <array>
#include <cmath>
#include <cstdint>

namespace mft::chain {

enum class InputVerdict { Ok, NonFinite, OutOfRange, BadEnum };

inline const char* toString(InputVerdict v) {
  switch (v) {
    case InputVerdict::Ok: return "ok";
    case InputVerdict::NonFinite: return "non-finite";
    case InputVerdict::OutOfRange: return "out of range";
    case InputVerdict::BadEnum: return "unknown mode";
  }
  return "?";
}

// `mode`: 0 normal, 1 damping (msg::COMMAND_MODE_*). `peak_torque`: the actuators' output peak torque; the
// WBC never commands more (its limit is a fraction of it), so a larger value is garbage, not a saturation.
inline InputVerdict checkJointCommand(const std::array<double, 4>& tau, std::uint8_t mode, double peak_torque) {
  for (double t : tau)
    if (!std::isfinite(t)) return InputVerdict::NonFinite;
  if (mode > 1) return InputVerdict::BadEnum;
  for (double t : tau)
    if (std::abs(t) > peak_torque * (1.0 + 1e-9)) return InputVerdict::OutOfRange;
  return InputVerdict::Ok;
}

// `trigger`: 0 at a time, 1 at the next lift-off of `leg` (0 right, 1 left).
inline InputVerdict checkDisturbance(double impulse_Ns, std::uint8_t trigger, double time_s, int leg,
                                     double max_impulse_Ns) {
  if (!std::isfinite(impulse_Ns) || !std::isfinite(time_s)) return InputVerdict::NonFinite;
  if (trigger > 1 || (trigger == 1 && (leg < 0 || leg > 1))) return InputVerdict::BadEnum;
  if (std::abs(impulse_Ns) > max_impulse_Ns || time_s < 0.0) return InputVerdict::OutOfRange;
  return InputVerdict::Ok;
}

}  // namespace mft::chain
