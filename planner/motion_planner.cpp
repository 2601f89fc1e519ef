#include "planner/motion_planner.hpp"

#include <algorithm>
#include <cmath>

#include "planner/base_reference.hpp"
#include "planner/foot_placement.hpp"
#include "planner/swing_trajectory.hpp"

namespace mft::planner {

namespace {
OperatorCommand initialCommand(const CommandParams& p) { return {p.initial_height_m, p.initial_speed_mps, p.initial_mode}; }
}  // namespace

MotionPlanner::MotionPlanner(const PlannerConfig& config, const model::RobotDescription& robot)
    : config_(config),
      gravity_(robot.gravity_mps2),
      gate_(commandLimits(robot, config.command, config.source_file), initialCommand(config.command)),
      schedule_(config.gait) {}

const PlanOutput& MotionPlanner::update(const PlannerState& s) {
  if (!started_) {
    started_ = true;
    schedule_.reset(s.time_s);
    hold_ = s.foot_pos;
    z_ref_ = s.base_z;
    last_time_ = s.time_s;
    target_frozen_ = false;
    out_ = PlanOutput{};
  }
  const double dt = std::max(0.0, s.time_s - last_time_);
  last_time_ = s.time_s;
  tick_dt_ = dt;
  const OperatorCommand& cmd = gate_.current();

  const ScheduleEvents ev = schedule_.update(s.time_s, s.contact, cmd.mode != LocomotionMode::Stand);
  if (ev.touchdown_leg >= 0) hold_[ev.touchdown_leg] = s.foot_pos[ev.touchdown_leg];
  if (ev.liftoff_leg >= 0) {
    liftoff_ = s.foot_pos[ev.liftoff_leg];
    target_frozen_ = false;
  }

  out_.tick = s.tick;
  out_.time_s = s.time_s;
  out_.mode = cmd.mode;
  out_.step_index = schedule_.stepIndex();
  out_.phase = schedule_.phase();
  out_.stance_leg = schedule_.stanceLeg();
  out_.swing_extended = schedule_.extended();
  out_.last_touchdown = schedule_.lastTouchdown();

  // (18): z_ref = z_cmd (reached at a bounded rate), pitch_ref = 0.
  const HeightPitchReference base = heightPitchReference(z_ref_, cmd.z_cmd, config_.command.height_rate_mps, dt);
  z_ref_ = base.base_z[0];
  out_.base_z = base.base_z;
  out_.base_pitch = base.base_pitch;
  // Standing: base x over the midpoint of the stance feet (a double-support task; the paper's (18) plans only
  // z and pitch, and with both feet down nothing else would stop the base drifting).
  out_.base_x = {0.5 * (hold_[0].x() + hold_[1].x()), 0.0, 0.0};
  out_.hold_base_x = cmd.mode == LocomotionMode::Stand && !schedule_.inSwing();

  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    FootReference& f = out_.foot[leg];
    f.stance = schedule_.legInStance(leg);
    f.pos = hold_[leg];
    f.vel.setZero();
    f.acc.setZero();
  }
  if (schedule_.inSwing()) {
    planSwing(s, schedule_.swingLeg());
  } else {
    out_.target_x = 0.0;
    out_.predicted_com.setZero();
    out_.desired_com_speed = 0.0;
  }
  return out_;
}

void MotionPlanner::planSwing(const PlannerState& s, int swing_leg) {
  const GaitParams& gait = config_.gait;
  const Eigen::Vector2d& support = hold_[1 - swing_leg];
  const OperatorCommand& cmd = gate_.current();

  if (!target_frozen_) {
    // (19) with the LIP prediction of the pre-impact CoM state, relative to the support foot.
    const double lambda = lipLambda(gravity_, s.com.y() - support.y());
    const double remaining = std::max(0.0, gait.step_duration_s - schedule_.timeInSwing());
    const LipState pre = lipPredict({s.com.x() - support.x(), s.com_vel.x()}, lambda, remaining);
    const double v_avg = cmd.mode == LocomotionMode::Walk ? cmd.v_cmd : 0.0;
    out_.desired_com_speed = hlipPreImpactSpeed(v_avg, lambda, gait.step_duration_s, gait.double_support_s);
    out_.predicted_com = {support.x() + pre.x, pre.xd};
    out_.target_x = footPlacement(out_.predicted_com.x(), pre.xd, out_.desired_com_speed, config_.placement);
    if (schedule_.phase() >= config_.swing.replan_until_phase) target_frozen_ = true;
  }

  SwingSpec spec;
  spec.liftoff = liftoff_;
  spec.target_x = out_.target_x;
  spec.ground_z = support.y();  // flat-ground assumption: land at the support foot's height
  spec.duration_s = gait.step_duration_s;
  spec.lift_height_m = config_.swing.lift_height_m;
  spec.touchdown_speed_mps = config_.swing.touchdown_speed_mps;
  const SwingSample sample = evaluateSwing(spec, schedule_.timeInSwing());
  FootReference& f = out_.foot[swing_leg];
  f.pos = sample.pos;
  f.vel = sample.vel;
  f.acc = sample.acc;
  if (!schedule_.extended() || config_.swing.late_replan_speed_mps <= 0.0) {
    late_active_ = false;
    return;
  }
  // Late touchdown (e.g. a blind step down): the frozen target was planned for the nominal touchdown time while
  // the base keeps moving as the foot looks for the ground. (19) from the CoM state now (the touchdown is due
  // now: no LIP prediction), and the foot moves toward it at most late_replan_speed_mps.
  const double lambda = lipLambda(gravity_, s.com.y() - support.y());
  const double v_avg = cmd.mode == LocomotionMode::Walk ? cmd.v_cmd : 0.0;
  const double xd_des = hlipPreImpactSpeed(v_avg, lambda, gait.step_duration_s, gait.double_support_s);
  const double now_target = footPlacement(s.com.x(), s.com_vel.x(), xd_des, config_.placement);
  if (!late_active_) {
    late_active_ = true;
    late_x_ = out_.target_x;
  }
  const double dt = std::min(tick_dt_, 0.01);
  const double max_move = config_.swing.late_replan_speed_mps * dt;
  const double move = std::clamp(now_target - late_x_, -max_move, max_move);
  late_x_ += move;
  f.pos.x() = late_x_;
  f.vel.x() = dt > 0.0 ? move / dt : 0.0;
  f.acc.x() = 0.0;
  out_.target_x = late_x_;
}

}  // namespace mft::planner
