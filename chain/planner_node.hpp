#pragma once
// The planner stage of the chain: estimate(k) -> the scenario's commands due at t_k -> plan(k) -> the WBC's
// reference(k) (the one PlanOutput -> WbcReference mapping, chain/reference_from_plan.hpp). Operator commands
// from outside the scenario go to planner() between applyScenarioCommands() and plan(): the operator has the
// last word within a tick.
#include <cstdint>

#include "chain/command_schedule.hpp"
#include "chain/scenario.hpp"
#include "planner/motion_planner.hpp"
#include "wbc/wbc_reference.hpp"

namespace mft::chain {

class PlannerNode {
 public:
  PlannerNode(const planner::PlannerConfig& config, const model::RobotDescription& robot, const Scenario& scenario)
      : planner_(config, robot), state_builder_(robot), schedule_(scenario.commands) {}

  // Gives the planner every scenario command due at `time_s`; on_result(command, result) for each (the caller
  // reports a rejected one).
  template <class OnResult>
  void applyScenarioCommands(double time_s, OnResult&& on_result) {
    schedule_.applyDue(time_s, [&](const ScenarioCommand& c) {
      const planner::OperatorCommand cmd = toOperatorCommand(c);
      on_result(cmd, planner_.setCommand(cmd));
    });
  }
  // Plans tick `estimate.tick` and maps the plan to the WBC's reference (tick set).
  const wbc::WbcReference& plan(const model::RobotStateEstimate& estimate);
  // A new clock: the scenario's commands replay, and the plan starts again from the robot's current state.
  void restart();

  planner::MotionPlanner& planner() { return planner_; }
  const planner::MotionPlanner& planner() const { return planner_; }
  const planner::PlanOutput& output() const { return planner_.output(); }
  const wbc::WbcReference& reference() const { return reference_; }

 private:
  planner::MotionPlanner planner_;
  planner::PlannerStateBuilder state_builder_;
  CommandSchedule schedule_;
  wbc::WbcReference reference_;
};

}  // namespace mft::chain
