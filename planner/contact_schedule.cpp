#include "planner/contact_schedule.hpp"

#include <algorithm>

namespace mft::planner {

void ContactSchedule::reset(double time_s) {
  initialized_ = true;
  time_ = time_s;
  swing_leg_ = -1;
  next_swing_leg_ = gait_.first_swing_leg;
  double_support_start_ = time_s;
  ready_to_lift_ = true;  // starting from a stand: no double-support wait before the first step
  step_index_ = 0;
  last_touchdown_ = TouchdownKind::None;
}

double ContactSchedule::phase() const {
  return inSwing() ? std::clamp(timeInSwing() / gait_.step_duration_s, 0.0, 1.0) : 0.0;
}

ScheduleEvents ContactSchedule::update(double time_s, const std::array<bool, model::kNumLegs>& contact,
                                       bool stepping) {
  if (!initialized_) reset(time_s);
  time_ = time_s;
  ScheduleEvents ev;
  const double T = gait_.step_duration_s;

  if (inSwing()) {
    const double t = timeInSwing();
    const bool landed = contact[swing_leg_] && t >= gait_.min_touchdown_phase * T;
    const bool forced = !landed && t >= T + gait_.max_extension_s;
    if (landed || forced) {
      last_touchdown_ = forced ? TouchdownKind::Forced : (t < T ? TouchdownKind::Early : TouchdownKind::Late);
      ev.touchdown_leg = swing_leg_;
      next_swing_leg_ = 1 - swing_leg_;
      swing_leg_ = -1;
      double_support_start_ = time_s;
      ready_to_lift_ = false;
    }
  }

  if (!inSwing()) {
    if (!ready_to_lift_ && time_s - double_support_start_ >= gait_.double_support_s) ready_to_lift_ = true;
    if (stepping && ready_to_lift_) {
      swing_leg_ = next_swing_leg_;
      liftoff_time_ = time_s;
      ++step_index_;
      ev.liftoff_leg = swing_leg_;
    }
  }
  return ev;
}

}  // namespace mft::planner
