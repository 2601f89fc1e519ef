#include "planner/planner_state.hpp"

namespace mft::planner {

PlannerStateBuilder::PlannerStateBuilder(const model::RobotDescription& robot) : model_(model::buildBipedModel(robot)) {}

PlannerState PlannerStateBuilder::build(const model::RobotStateEstimate& est) {
  model::updateModel(model_, est.q, est.qd, &data_);
  PlannerState s;
  s.tick = est.tick;
  s.time_s = est.time_s;
  s.base_z = est.q[model::kBaseZ];
  s.com = data_.com;
  s.com_vel = data_.com_vel;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    s.foot_pos[leg] = data_.foot_pos.segment<2>(2 * leg);
    s.foot_vel[leg] = data_.foot_vel.segment<2>(2 * leg);
  }
  s.contact = est.contact;
  return s;
}

}  // namespace mft::planner
