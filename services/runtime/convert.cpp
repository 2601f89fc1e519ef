#include "services/runtime/convert.hpp"

#include "chain/reference_from_plan.hpp"

namespace mft::services {

namespace {
template <class Array, class Vec>
void copyIn(const Array& a, Vec* v) {
  for (std::size_t i = 0; i < a.size(); ++i) (*v)[static_cast<long>(i)] = a[i];
}
template <class Vec, class Array>
void copyOut(const Vec& v, Array* a) {
  for (std::size_t i = 0; i < a->size(); ++i) (*a)[i] = v[static_cast<long>(i)];
}
}  // namespace

void toMsg(const model::SensorReadings& in, msg::SensorData* out) {
  out->tick(in.tick);
  out->stamp_ns(toStampNs(in.time_s));
  out->actuated_pos(in.actuated_pos);
  out->actuated_vel(in.actuated_vel);
  out->passive_pos(in.passive_pos);
  out->passive_vel(in.passive_vel);
  out->sea_torque(in.sea_torque);
  out->gyro_pitch_rate(in.gyro_pitch_rate);
  out->accel(in.accel);
  out->contact(in.contact);
}

void fromMsg(const msg::SensorData& in, model::SensorReadings* out) {
  out->tick = in.tick();
  out->time_s = fromStampNs(in.stamp_ns());
  out->actuated_pos = in.actuated_pos();
  out->actuated_vel = in.actuated_vel();
  out->passive_pos = in.passive_pos();
  out->passive_vel = in.passive_vel();
  out->sea_torque = in.sea_torque();
  out->gyro_pitch_rate = in.gyro_pitch_rate();
  out->accel = in.accel();
  out->contact = in.contact();
}

void toMsg(const model::GroundTruthState& in, msg::GroundTruth* out) {
  out->tick(in.tick);
  out->stamp_ns(toStampNs(in.time_s));
  copyOut(in.q, &out->q());
  copyOut(in.qd, &out->qd());
  copyOut(in.contact_force, &out->contact_force());
  out->lti(in.lti);
}

void fromMsg(const msg::GroundTruth& in, model::GroundTruthState* out) {
  out->tick = in.tick();
  out->time_s = fromStampNs(in.stamp_ns());
  copyIn(in.q(), &out->q);
  copyIn(in.qd(), &out->qd);
  copyIn(in.contact_force(), &out->contact_force);
  out->lti = in.lti();
}

void toMsg(const model::RobotStateEstimate& in, msg::RobotState* out) {
  out->tick(in.tick);
  out->stamp_ns(toStampNs(in.time_s));
  copyOut(in.q, &out->q());
  copyOut(in.qd, &out->qd());
  out->contact(in.contact);
}

void fromMsg(const msg::RobotState& in, model::RobotStateEstimate* out) {
  out->tick = in.tick();
  out->time_s = fromStampNs(in.stamp_ns());
  copyIn(in.q(), &out->q);
  copyIn(in.qd(), &out->qd);
  out->contact = in.contact();
}

void toMsg(const model::ActuatorCommand& in, std::uint64_t stamp_ns, std::uint64_t seq, msg::JointCommand* out) {
  out->tick(in.tick);
  out->stamp_ns(stamp_ns);
  out->seq(seq);
  copyOut(in.tau, &out->tau());
  out->mode(in.mode == model::CommandMode::Damping ? msg::COMMAND_MODE_DAMPING : msg::COMMAND_MODE_NORMAL);
}

void fromMsg(const msg::JointCommand& in, model::ActuatorCommand* out) {
  out->tick = in.tick();
  copyIn(in.tau(), &out->tau);
  out->mode = in.mode() == msg::COMMAND_MODE_DAMPING ? model::CommandMode::Damping : model::CommandMode::Normal;
}

void toMsg(const planner::PlanOutput& in, msg::Reference* out) {
  // The controller's part goes through the shared mapping (chain/reference_from_plan.hpp), the one the
  // in-process closed loop uses too; the rest is schedule information for recording.
  toMsg(in, chain::referenceFromPlan(in), out);
}

void toMsg(const planner::PlanOutput& in, const wbc::WbcReference& r, msg::Reference* out) {
  out->tick(in.tick);
  out->stamp_ns(toStampNs(in.time_s));
  out->step_index(in.step_index);
  out->phase(in.phase);
  out->stance_leg(static_cast<std::int16_t>(in.stance_leg));
  out->foot_in_stance(r.foot_in_stance);
  out->base_z({r.base_z.pos, r.base_z.vel, r.base_z.acc});
  out->base_pitch({r.base_pitch.pos, r.base_pitch.vel, r.base_pitch.acc});
  copyOut(r.foot_pos, &out->foot_pos());
  copyOut(r.foot_vel, &out->foot_vel());
  copyOut(r.foot_acc, &out->foot_acc());
  out->base_x({r.base_x.pos, r.base_x.vel, r.base_x.acc});
  out->hold_base_x(r.hold_base_x);
}

void fromMsg(const msg::Reference& in, wbc::WbcReference* out) {
  out->tick = in.tick();
  out->foot_in_stance = in.foot_in_stance();
  out->base_z = {in.base_z()[0], in.base_z()[1], in.base_z()[2]};
  out->base_pitch = {in.base_pitch()[0], in.base_pitch()[1], in.base_pitch()[2]};
  copyIn(in.foot_pos(), &out->foot_pos);
  copyIn(in.foot_vel(), &out->foot_vel);
  copyIn(in.foot_acc(), &out->foot_acc);
  out->base_x = {in.base_x()[0], in.base_x()[1], in.base_x()[2]};
  out->hold_base_x = in.hold_base_x();
}

void toMsg(const wbc::WbcDiagnostics& in, std::uint64_t stamp_ns, msg::WbcDiagnostics* out) {
  out->tick(in.tick);
  out->stamp_ns(stamp_ns);
  out->solve_time_us(in.solve_time_us);
  out->tick_time_us(in.tick_time_us);
  out->iterations(in.iterations);
  out->status(static_cast<std::int32_t>(in.status));
  out->active_constraints(in.active_constraints);
  out->slack_norm(in.slack_norm);
  out->task_error(in.task_error);
  out->lti(in.lti);
  out->raci(in.raci);
  out->safety_events(in.safety.events);
  out->holding(in.safety_mode == wbc::SafetyMode::Holding);
  out->damping(in.safety_mode == wbc::SafetyMode::Damping);
}

planner::LocomotionMode locomotionModeFromMsg(std::uint8_t mode) {
  return mode == msg::LOCOMOTION_WALK             ? planner::LocomotionMode::Walk
         : mode == msg::LOCOMOTION_STEP_IN_PLACE ? planner::LocomotionMode::StepInPlace
                                                  : planner::LocomotionMode::Stand;
}

void fromMsg(const msg::OperatorCommand& in, planner::OperatorCommand* out) {
  out->z_cmd = in.z_cmd();
  out->v_cmd = in.v_cmd();
  out->mode = locomotionModeFromMsg(in.mode());
}

}  // namespace mft::services
