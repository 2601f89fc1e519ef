// Library structs survive the trip through the DDS messages field by field (a field left out of a converter
// shows up here), including the planner -> Reference -> WBC reference path.
#include <gtest/gtest.h>

#include "services/runtime/convert.hpp"

using namespace mft;

namespace {
// `value` converted to the DDS message `Msg` and back.
template <class Msg, class T>
T roundTrip(const T& value) {
  Msg m;
  services::toMsg(value, &m);
  T back;
  services::fromMsg(m, &back);
  return back;
}
}  // namespace

TEST(Convert, SensorReadingsRoundTrip) {
  model::SensorReadings s;
  s.tick = 77;
  s.time_s = 0.077;
  for (int i = 0; i < 4; ++i) {
    s.actuated_pos[i] = 0.1 * i + 0.01;
    s.actuated_vel[i] = -0.2 * i;
    s.passive_pos[i] = 1.1 + i;
    s.passive_vel[i] = 3.0 - i;
    s.sea_torque[i] = 10.0 * i - 5;
  }
  s.gyro_pitch_rate = 0.3;
  s.accel = {0.5, 9.7};
  s.contact = {true, false};
  const model::SensorReadings back = roundTrip<msg::SensorData>(s);
  EXPECT_EQ(back.tick, 77u);
  EXPECT_NEAR(back.time_s, 0.077, 1e-12);
  EXPECT_EQ(back.actuated_pos, s.actuated_pos);
  EXPECT_EQ(back.actuated_vel, s.actuated_vel);
  EXPECT_EQ(back.passive_pos, s.passive_pos);
  EXPECT_EQ(back.passive_vel, s.passive_vel);
  EXPECT_EQ(back.sea_torque, s.sea_torque);
  EXPECT_EQ(back.gyro_pitch_rate, 0.3);
  EXPECT_EQ(back.accel, s.accel);
  EXPECT_EQ(back.contact, s.contact);
}

TEST(Convert, StateTruthAndCommandRoundTrip) {
  model::RobotStateEstimate st;
  st.tick = 5;
  st.q = model::VectorQ::LinSpaced(-1, 1);
  st.qd = model::VectorQ::LinSpaced(2, 3);
  st.contact = {false, true};
  const model::RobotStateEstimate st2 = roundTrip<msg::RobotState>(st);
  EXPECT_EQ(st2.q, st.q);
  EXPECT_EQ(st2.qd, st.qd);
  EXPECT_EQ(st2.contact, st.contact);

  model::GroundTruthState gt;
  gt.q = model::VectorQ::Constant(0.25);
  gt.contact_force << 1, 2, 3, 4;
  gt.lti = {0.8, 0.6};
  const model::GroundTruthState gt2 = roundTrip<msg::GroundTruth>(gt);
  EXPECT_EQ(gt2.q, gt.q);
  EXPECT_EQ(gt2.contact_force, gt.contact_force);
  EXPECT_EQ(gt2.lti, gt.lti);

  model::ActuatorCommand c;
  c.tick = 9;
  c.tau << 1.5, -2.5, 3.5, -4.5;
  c.mode = model::CommandMode::Damping;
  msg::JointCommand mc;
  services::toMsg(c, 9000000, 12, &mc);
  EXPECT_EQ(mc.seq(), 12u);
  model::ActuatorCommand c2;
  services::fromMsg(mc, &c2);
  EXPECT_EQ(c2.tick, 9u);
  EXPECT_EQ(c2.tau, c.tau);
  EXPECT_EQ(c2.mode, model::CommandMode::Damping);
}

TEST(Convert, PlanToWbcReference) {
  planner::PlanOutput p;
  p.tick = 3;
  p.base_z = {0.42, 0.01, -0.2};
  p.base_pitch = {0.0, 0.1, 0.2};
  p.foot[0].stance = true;
  p.foot[0].pos = {0.05, 0.0};
  p.foot[1].stance = false;
  p.foot[1].pos = {-0.1, 0.04};
  p.foot[1].vel = {0.5, 0.2};
  p.foot[1].acc = {-3.0, 1.0};
  p.stance_leg = 0;
  p.base_x = {0.01, -0.02, 0.3};
  p.hold_base_x = true;
  msg::Reference m;
  services::toMsg(p, &m);
  EXPECT_EQ(m.stance_leg(), 0);
  wbc::WbcReference r;
  services::fromMsg(m, &r);
  EXPECT_EQ(r.tick, 3u);
  EXPECT_TRUE(r.foot_in_stance[0]);
  EXPECT_FALSE(r.foot_in_stance[1]);
  EXPECT_DOUBLE_EQ(r.base_z.pos, 0.42);
  EXPECT_DOUBLE_EQ(r.base_z.acc, -0.2);
  EXPECT_DOUBLE_EQ(r.base_pitch.vel, 0.1);
  EXPECT_EQ(r.foot_pos, p.footPos());
  EXPECT_EQ(r.foot_vel, p.footVel());
  EXPECT_EQ(r.foot_acc, p.footAcc());
  EXPECT_DOUBLE_EQ(r.foot_acc[2], -3.0);
  EXPECT_DOUBLE_EQ(m.base_x()[0], 0.01);
  EXPECT_TRUE(m.hold_base_x());
  EXPECT_DOUBLE_EQ(r.base_x.pos, 0.01);
  EXPECT_DOUBLE_EQ(r.base_x.vel, -0.02);
  EXPECT_DOUBLE_EQ(r.base_x.acc, 0.3);
  EXPECT_TRUE(r.hold_base_x);
  p.hold_base_x = false;
  services::toMsg(p, &m);
  services::fromMsg(m, &r);
  EXPECT_FALSE(r.hold_base_x);
}

TEST(Convert, OperatorCommandModeOctets) {
  msg::OperatorCommand m;
  m.z_cmd(0.41);
  m.v_cmd(0.25);
  planner::OperatorCommand c;
  const std::pair<std::uint8_t, planner::LocomotionMode> octets[] = {
      {msg::LOCOMOTION_STAND, planner::LocomotionMode::Stand},
      {msg::LOCOMOTION_STEP_IN_PLACE, planner::LocomotionMode::StepInPlace},
      {msg::LOCOMOTION_WALK, planner::LocomotionMode::Walk},
      {static_cast<std::uint8_t>(msg::LOCOMOTION_WALK + 1), planner::LocomotionMode::Stand}};  // refused upstream
  for (const auto& [octet, mode] : octets) {
    m.mode(octet);
    services::fromMsg(m, &c);
    EXPECT_EQ(c.mode, mode) << "octet " << int(octet);
    EXPECT_EQ(c.z_cmd, 0.41);
    EXPECT_EQ(c.v_cmd, 0.25);
  }
}

TEST(Convert, WbcDiagnosticsToMsg) {
  wbc::WbcDiagnostics d;
  d.tick = 42;
  d.solve_time_us = 3.5;
  d.tick_time_us = 12.25;
  d.iterations = 7;
  d.status = qp::QpStatus::Optimal;
  d.active_constraints = 4;
  d.slack_norm = 1e-3;
  d.task_error = {1, 2, 3, 4, 5, 6};
  d.lti = {0.7, 0.8};
  d.raci = {2.5, 3.5};
  d.safety.events = 2;
  d.safety_mode = wbc::SafetyMode::Damping;
  msg::WbcDiagnostics m;
  services::toMsg(d, 42000000, &m);
  EXPECT_EQ(m.tick(), 42u);
  EXPECT_EQ(m.stamp_ns(), 42000000u);
  EXPECT_EQ(m.solve_time_us(), 3.5);
  EXPECT_EQ(m.tick_time_us(), 12.25);
  EXPECT_EQ(m.iterations(), 7);
  EXPECT_EQ(m.status(), static_cast<std::int32_t>(qp::QpStatus::Optimal));
  EXPECT_EQ(m.active_constraints(), 4);
  EXPECT_EQ(m.slack_norm(), 1e-3);
  EXPECT_EQ(m.task_error()[5], 6.0);
  EXPECT_EQ(m.lti()[1], 0.8);
  EXPECT_EQ(m.raci()[0], 2.5);
  EXPECT_EQ(m.safety_events(), 2u);
  EXPECT_FALSE(m.holding());
  EXPECT_TRUE(m.damping());
}
