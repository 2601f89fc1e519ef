#include "chain/planner_node.hpp"

#include "chain/reference_from_plan.hpp"

namespace mft::chain {

const wbc::WbcReference& PlannerNode::plan(const model::RobotStateEstimate& estimate) {
  reference_ = referenceFromPlan(planner_.update(state_builder_.build(estimate)));
  reference_.tick = estimate.tick;
  return reference_;
}

void PlannerNode::restart() {
  schedule_.restart();
  planner_.reset();
}

}  // namespace mft::chain
