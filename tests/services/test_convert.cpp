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
