#pragma once
// Contact schedule: which foot swings, the phase of the swing, and touchdown detection from the state.
//   double support --(stepping, after double_support_s)--> swing(leg) --(touchdown)--> double support, other leg next
// Touchdown: the swing foot's contact flag once phase >= min_touchdown_phase (early if before the nominal end);
// without contact the swing is extended (the trajectory keeps descending) for up to max_extension_s, then the
// swap is forced. With double_support_s = 0 the next lift-off happens in the same update as the touchdown.
#include <array>
#include <cstdint>

#include "planner/planner_config.hpp"

namespace mft::planner {

struct ScheduleEvents {
  int touchdown_leg = -1;  // leg that landed in this update, -1 if none
  int liftoff_leg = -1;    // leg that lifted in this update, -1 if none
};

class ContactSchedule {
 public:
  explicit ContactSchedule(const GaitParams& gait) : gait_(gait) {}

  // Double support (standing) from time t; the next swing is the configured first leg.
  void reset(double time_s);
  // `stepping` false finishes a swing in progress and then stays in double support.
  ScheduleEvents update(double time_s, const std::array<bool, model::kNumLegs>& contact, bool stepping);

  bool inSwing() const { return swing_leg_ >= 0; }
  int swingLeg() const { return swing_leg_; }
  int stanceLeg() const { return swing_leg_ < 0 ? -1 : 1 - swing_leg_; }
  bool legInStance(int leg) const { return leg != swing_leg_; }
  double timeInSwing() const { return inSwing() ? time_ - liftoff_time_ : 0.0; }
  double phase() const;             // timeInSwing / T clamped to [0, 1]; 0 in double support
  bool extended() const { return inSwing() && timeInSwing() > gait_.step_duration_s; }
  std::uint64_t stepIndex() const { return step_index_; }
  TouchdownKind lastTouchdown() const { return last_touchdown_; }
  const GaitParams& gait() const { return gait_; }

 private:
  GaitParams gait_;
  bool initialized_ = false;
  double time_ = 0.0;
  int swing_leg_ = -1;
  int next_swing_leg_ = model::kRightLeg;
  double liftoff_time_ = 0.0;
  double double_support_start_ = 0.0;
  bool ready_to_lift_ = true;  // false right after a touchdown until double_support_s has elapsed
  std::uint64_t step_index_ = 0;
  TouchdownKind last_touchdown_ = TouchdownKind::None;
};

}  // namespace mft::planner
