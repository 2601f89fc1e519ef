#pragma once
// Every floating-point field of a received message must be finite and physically plausible (|v| <= 1e4 in
// SI units: no 10 km position, 10 km/s speed or 10 kN m torque on a 0.4 m robot) before a service lets it
// overwrite its state (docs/results/faults.md): such a sample is refused and counted, the service keeps its last good
// input, and the real sample of the same tick is still answered. Wrong values inside the plausible range
// cannot be told from real ones here: that is what DDS Security's access control is for (docs/guide/security.md).
// One overload per input topic.
#include <cmath>

#include "idl/msg_types.hpp"

namespace mft::services {

constexpr double kMaxPlausible = 1e4;

namespace detail {
inline bool ok(double v) { return std::isfinite(v) && std::abs(v) <= kMaxPlausible; }
template <class A>
bool finiteAll(const A& a) {
  for (double v : a)
    if (!ok(v)) return false;
  return true;
}
}  // namespace detail

inline bool validInput(const msg::SensorData& m) {
  using detail::finiteAll;
  return finiteAll(m.actuated_pos()) && finiteAll(m.actuated_vel()) && finiteAll(m.passive_pos()) &&
         finiteAll(m.passive_vel()) && finiteAll(m.sea_torque()) && detail::ok(m.gyro_pitch_rate()) &&
         finiteAll(m.accel());
}
inline bool validInput(const msg::GroundTruth& m) {
  using detail::finiteAll;
  for (double f : m.contact_force())  // impacts may be large: finite is all that is asked
    if (!std::isfinite(f)) return false;
  return finiteAll(m.q()) && finiteAll(m.qd()) && finiteAll(m.lti());
}
inline bool validInput(const msg::RobotState& m) { return detail::finiteAll(m.q()) && detail::finiteAll(m.qd()); }
inline bool validInput(const msg::Reference& m) {
  using detail::finiteAll;
  return m.stance_leg() >= -1 && m.stance_leg() <= 1 && detail::ok(m.phase()) && finiteAll(m.base_z()) && finiteAll(m.base_pitch()) && finiteAll(m.foot_pos()) &&
         finiteAll(m.foot_vel()) && finiteAll(m.foot_acc()) && finiteAll(m.base_x());
}
inline bool validInput(const msg::OperatorCommand& m) { return detail::ok(m.z_cmd()) && detail::ok(m.v_cmd()); }

}  // namespace mft::services
