#pragma once
// Every floating-point field of a received message must be finite before a service lets it overwrite its
// state (docs/faults.md): a non-finite sample is refused and counted, the service keeps its last good input,
// and the real sample of the same tick is still answered. One overload per input topic.
#include <cmath>

#include "MftMsgs.h"

namespace mft::services {

namespace detail {
template <class A>
bool finiteAll(const A& a) {
  for (double v : a)
    if (!std::isfinite(v)) return false;
  return true;
}
}  // namespace detail

inline bool finiteMsg(const msg::SensorData& m) {
  using detail::finiteAll;
  return finiteAll(m.actuated_pos()) && finiteAll(m.actuated_vel()) && finiteAll(m.passive_pos()) &&
         finiteAll(m.passive_vel()) && finiteAll(m.sea_torque()) && std::isfinite(m.gyro_pitch_rate()) &&
         finiteAll(m.accel());
}
inline bool finiteMsg(const msg::GroundTruth& m) {
  using detail::finiteAll;
  return finiteAll(m.q()) && finiteAll(m.qd()) && finiteAll(m.contact_force()) && finiteAll(m.lti());
}
inline bool finiteMsg(const msg::RobotState& m) { return detail::finiteAll(m.q()) && detail::finiteAll(m.qd()); }
inline bool finiteMsg(const msg::Reference& m) {
  using detail::finiteAll;
  return std::isfinite(m.phase()) && finiteAll(m.base_z()) && finiteAll(m.base_pitch()) && finiteAll(m.foot_pos()) &&
         finiteAll(m.foot_vel()) && finiteAll(m.foot_acc()) && finiteAll(m.base_x());
}
inline bool finiteMsg(const msg::OperatorCommand& m) { return std::isfinite(m.z_cmd()) && std::isfinite(m.v_cmd()); }

}  // namespace mft::services
