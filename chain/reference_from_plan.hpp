#pragma once
// The one mapping from the planner's output to the WBC's reference (the content of the Reference topic).
// Header-only and plain data on both sides, so the DDS services (through msg::Reference) and the in-process
// closed loop (chain/closed_loop.hpp) hand the controller exactly the same numbers. It lives in chain/, the floor
// that joins the planner and the controller: wbc/ depends on model/ alone.
#include "planner/plan_output.hpp"
#include "wbc/wbc_reference.hpp"

namespace mft::chain {

inline wbc::WbcReference referenceFromPlan(const planner::PlanOutput& plan) {
  wbc::WbcReference ref;
  ref.tick = plan.tick;
  for (int leg = 0; leg < model::kNumLegs; ++leg) ref.foot_in_stance[leg] = plan.foot[leg].stance;
  ref.base_z = {plan.base_z[0], plan.base_z[1], plan.base_z[2]};
  ref.base_pitch = {plan.base_pitch[0], plan.base_pitch[1], plan.base_pitch[2]};
  ref.base_x = {plan.base_x[0], plan.base_x[1], plan.base_x[2]};
  ref.hold_base_x = plan.hold_base_x;
  ref.foot_pos = plan.footPos();
  ref.foot_vel = plan.footVel();
  ref.foot_acc = plan.footAcc();
  return ref;
}

}  // namespace mft::chain
