#pragma once
// The paper's motion planner (section IV-A): (18) for the base, support foot held at its touchdown position,
// (19) foot placement with the LIP-predicted pre-impact CoM state, cubic swing trajectory, contact schedule.
// Per Remark 1 it re-plans only the swing foot; it does not react to other state changes.
//
// Additions to the paper, all configurable: the height reference is rate-limited toward the command (a step in
// z_cmd would otherwise be a step in the reference), the (19) target is frozen late in the swing, the
// offset of the target from the CoM is clamped to the legs' reach, and a late touchdown (the swing extended past
// T looking for the ground) moves the foot toward (19) re-planned from the current CoM state at a bounded speed.
#include "model/robot_description.hpp"
#include "planner/contact_schedule.hpp"
#include "planner/operator_command.hpp"
#include "planner/plan_output.hpp"
#include "planner/planner_config.hpp"
#include "planner/planner_state.hpp"
#include "planner/planner_tuning.hpp"

namespace mft::planner {

class MotionPlanner {
 public:
  // Throws mft::config::ConfigError if the configured command range or initial command does not fit the robot.
  MotionPlanner(const PlannerConfig& config, const model::RobotDescription& robot);

  // Validates and applies an operator command; a rejected one leaves the last valid command in force.
  CommandResult setCommand(const OperatorCommand& cmd) { return gate_.submit(cmd); }
  const OperatorCommand& command() const { return gate_.current(); }
  const CommandLimits& limits() const { return gate_.limits(); }

  // One planning tick (build the state from a RobotStateEstimate with PlannerStateBuilder). The first call after construction or reset() starts from the current state (both feet
  // held where they are, height reference at the current base height).
  const PlanOutput& update(const PlannerState& state);

  void reset() { started_ = false; }

  // Live tuning: swing, foot placement and height rate from the next update() on (copies doubles: allocation-free,
  // for a tick boundary). Judge a change with applyPlannerOverride first (planner_tuning.hpp).
  void setTuning(const PlannerTuning& t) {
    config_.swing = t.swing;
    config_.placement = t.placement;
    config_.command.height_rate_mps = t.height_rate_mps;
  }
  const PlanOutput& output() const { return out_; }
  const ContactSchedule& schedule() const { return schedule_; }
  const PlannerConfig& config() const { return config_; }

 private:
  void planSwing(const PlannerState& state, int swing_leg);

  PlannerConfig config_;
  double gravity_;
  CommandGate gate_;
  ContactSchedule schedule_;
  bool started_ = false;
  double last_time_ = 0.0;
  double z_ref_ = 0.0;
  std::array<Eigen::Vector2d, model::kNumLegs> hold_{};  // support-foot positions (at touchdown)
  Eigen::Vector2d liftoff_{0, 0};
  bool target_frozen_ = false;
  bool late_active_ = false;  // late touchdown: the swing foot follows (19) re-planned from the current state
  double late_x_ = 0.0;
  double tick_dt_ = 0.0;
  PlanOutput out_;
};

}  // namespace mft::planner
