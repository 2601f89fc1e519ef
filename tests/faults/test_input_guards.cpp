// The checks between the network and the robot (docs/results/faults.md): the simulator's actuator driver, the
// services' input plausibility and the tick gate. Pure logic, no DDS traffic.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "chain/input_guard.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/tick_gate.hpp"

using mft::chain::checkDisturbance;
using mft::chain::checkJointCommand;
using mft::chain::InputVerdict;
using mft::services::TickGate;
using mft::services::validInput;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPeak = 52.36;
}  // namespace

TEST(ActuatorDriver, AcceptsWhatTheWbcCommands) {
  EXPECT_EQ(checkJointCommand({1.0, -2.0, 30.0, -52.36}, 0, kPeak), InputVerdict::Ok);
  EXPECT_EQ(checkJointCommand({0.0, 0.0, 0.0, 0.0}, 1, kPeak), InputVerdict::Ok);  // damping
}

TEST(ActuatorDriver, RefusesNonFiniteTorquesInAnyJoint) {
  for (int j = 0; j < 4; ++j) {
    for (double bad : {kNaN, kInf, -kInf}) {
      std::array<double, 4> tau{1.0, 1.0, 1.0, 1.0};
      tau[static_cast<std::size_t>(j)] = bad;
      EXPECT_EQ(checkJointCommand(tau, 0, kPeak), InputVerdict::NonFinite) << j;
      EXPECT_EQ(checkJointCommand(tau, 1, kPeak), InputVerdict::NonFinite) << "damping mode is no excuse";
    }
  }
}

TEST(ActuatorDriver, RefusesTorquesBeyondThePeakAndUnknownModes) {
  EXPECT_EQ(checkJointCommand({kPeak * 1.001, 0, 0, 0}, 0, kPeak), InputVerdict::OutOfRange);
  EXPECT_EQ(checkJointCommand({0, 0, 0, -1e6}, 0, kPeak), InputVerdict::OutOfRange);
  EXPECT_EQ(checkJointCommand({0, 0, 0, 0}, 2, kPeak), InputVerdict::BadEnum);
  EXPECT_EQ(checkJointCommand({0, 0, 0, 0}, 99, kPeak), InputVerdict::BadEnum);
}

TEST(DisturbanceCheck, RefusesNonFiniteOversizedAndMalformedPushes) {
  EXPECT_EQ(checkDisturbance(3.0, 0, 1.5, -1, 200), InputVerdict::Ok);
  EXPECT_EQ(checkDisturbance(-3.0, 1, 0.0, 1, 200), InputVerdict::Ok);
  EXPECT_EQ(checkDisturbance(kNaN, 0, 1.0, 0, 200), InputVerdict::NonFinite);
  EXPECT_EQ(checkDisturbance(3.0, 0, kInf, 0, 200), InputVerdict::NonFinite);
  EXPECT_EQ(checkDisturbance(1e6, 0, 1.0, 0, 200), InputVerdict::OutOfRange);
  EXPECT_EQ(checkDisturbance(3.0, 0, -1.0, 0, 200), InputVerdict::OutOfRange);
  EXPECT_EQ(checkDisturbance(3.0, 9, 1.0, 0, 200), InputVerdict::BadEnum);
  EXPECT_EQ(checkDisturbance(3.0, 1, 1.0, 9, 200), InputVerdict::BadEnum);
}

TEST(InputPlausibility, EveryFloatingFieldOfEveryInputTopicIsChecked) {
  mft::msg::SensorData s;
  EXPECT_TRUE(validInput(s));
  s.accel()[1] = kNaN;
  EXPECT_FALSE(validInput(s));
  s.accel()[1] = 9.81;
  s.gyro_pitch_rate(2e4);
  EXPECT_FALSE(validInput(s));

  mft::msg::RobotState r;
  EXPECT_TRUE(validInput(r));
  r.qd()[10] = -kInf;
  EXPECT_FALSE(validInput(r));
  r.qd()[10] = 0;
  r.q()[1] = 1e6;
  EXPECT_FALSE(validInput(r));

  mft::msg::Reference ref;
  EXPECT_TRUE(validInput(ref));
  ref.foot_acc()[3] = kNaN;
  EXPECT_FALSE(validInput(ref));
  ref.foot_acc()[3] = 0;
  ref.stance_leg(7);
  EXPECT_FALSE(validInput(ref));
  ref.stance_leg(-1);
  EXPECT_TRUE(validInput(ref));

  mft::msg::GroundTruth g;
  g.contact_force()[1] = 5e4;  // a hard impact: large, but real
  EXPECT_TRUE(validInput(g));
  g.contact_force()[1] = kNaN;
  EXPECT_FALSE(validInput(g));

  mft::msg::OperatorCommand c;
  c.z_cmd(0.42);
  EXPECT_TRUE(validInput(c));
  c.v_cmd(kInf);
  EXPECT_FALSE(validInput(c));
}

TEST(TickGate, AnswersTheClockAndRepeats) {
  TickGate g(200);
  EXPECT_EQ(g.check(0), TickGate::Decision::Answer);
  g.answered(0);
  EXPECT_EQ(g.check(0), TickGate::Decision::Repeat);
  EXPECT_EQ(g.check(1), TickGate::Decision::Answer);
  g.answered(1);
  EXPECT_EQ(g.check(150), TickGate::Decision::Answer);  // a short stall: fine
  g.answered(150);
  EXPECT_EQ(g.check(149), TickGate::Decision::Stale);
}

TEST(TickGate, RefusesOneStraySampleFarAheadOrBehind) {
  TickGate g(200);
  g.answered(5000);
  EXPECT_EQ(g.check(1005001), TickGate::Decision::Refused);  // injected tick + 1e6
  EXPECT_EQ(g.check(5001), TickGate::Decision::Answer);      // the real clock goes on
  g.answered(5001);
  EXPECT_EQ(g.check(1005002), TickGate::Decision::Refused);  // interleaved forgeries never confirm
  EXPECT_EQ(g.check(5002), TickGate::Decision::Answer);
  g.answered(5002);
  EXPECT_EQ(g.check(3), TickGate::Decision::Refused);
  EXPECT_EQ(g.check(5003), TickGate::Decision::Answer);
  EXPECT_EQ(g.refused(), 3u);
  EXPECT_EQ(g.newClocks(), 0u);
}

TEST(TickGate, FollowsARestartedSimulatorAfterOneConfirmingTick) {
  TickGate g(200);
  g.answered(2481);
  EXPECT_EQ(g.check(0), TickGate::Decision::Refused);   // first sample of the new clock
  EXPECT_EQ(g.check(0), TickGate::Decision::NewClock);  // re-sent tick 0 confirms it
  EXPECT_EQ(g.last(), 0u);                              // adopted even before an answer
  g.answered(0);
  EXPECT_EQ(g.check(1), TickGate::Decision::Answer);
  TickGate h(200);
  h.answered(100);
  EXPECT_EQ(h.check(3100), TickGate::Decision::Refused);  // a 3 s stall of the simulator...
  EXPECT_EQ(h.check(3101), TickGate::Decision::Answer);   // ...costs one tick
  EXPECT_EQ(h.newClocks(), 1u);
}
