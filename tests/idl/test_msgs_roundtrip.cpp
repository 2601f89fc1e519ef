// The generated topic types: bounded (fixed size, no type objects), and every field survives a CDR round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>

#include "idl/msg_types.hpp"
#include "idl/msg_pubsub.hpp"

namespace {
template <class Msg, class PubSub>
Msg roundTrip(const Msg& in) {
  PubSub type;
  EXPECT_TRUE(type.is_bounded());
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.m_typeSize);
  EXPECT_TRUE(type.serialize(const_cast<Msg*>(&in), &payload));
  EXPECT_LE(payload.length, type.m_typeSize);
  Msg out;
  EXPECT_TRUE(type.deserialize(&payload, &out));
  return out;
}
}  // namespace

TEST(Msgs, SensorDataRoundTrip) {
  mft::msg::SensorData m;
  m.tick(123456789012ull);
  m.stamp_ns(987654321ull);
  for (int i = 0; i < 4; ++i) {
    m.actuated_pos()[i] = 0.1 * i - 0.7;
    m.passive_vel()[i] = -3.25 * i;
    m.sea_torque()[i] = 52.36 - i;
  }
  m.gyro_pitch_rate(-0.125);
  m.accel()[1] = 9.81;
  m.contact()[0] = true;
  const auto out = roundTrip<mft::msg::SensorData, mft::msg::SensorDataPubSubType>(m);
  EXPECT_TRUE(out == m);
  EXPECT_EQ(out.tick(), 123456789012ull);
  EXPECT_DOUBLE_EQ(out.sea_torque()[3], 49.36);
  EXPECT_TRUE(out.contact()[0]);
  EXPECT_FALSE(out.contact()[1]);
}

TEST(Msgs, JointCommandRoundTrip) {
  mft::msg::JointCommand m;
  m.tick(42);
  m.seq(43);
  m.tau({1.5, -2.5, 3.5, -4.5});
  m.mode(mft::msg::COMMAND_MODE_DAMPING);
  const auto out = roundTrip<mft::msg::JointCommand, mft::msg::JointCommandPubSubType>(m);
  EXPECT_TRUE(out == m);
  EXPECT_EQ(out.mode(), mft::msg::COMMAND_MODE_DAMPING);
}

TEST(Msgs, EveryTopicTypeIsBoundedAndRoundTrips) {
  mft::msg::GroundTruth gt;
  gt.q()[10] = 1.25;
  gt.lti()[1] = 0.7;
  EXPECT_TRUE((roundTrip<mft::msg::GroundTruth, mft::msg::GroundTruthPubSubType>(gt) == gt));
  mft::msg::RobotState rs;
  rs.qd()[2] = -0.5;
  rs.contact()[1] = true;
  EXPECT_TRUE((roundTrip<mft::msg::RobotState, mft::msg::RobotStatePubSubType>(rs) == rs));
  mft::msg::OperatorCommand oc;
  oc.z_cmd(0.42);
  oc.mode(mft::msg::LOCOMOTION_WALK);
  EXPECT_TRUE((roundTrip<mft::msg::OperatorCommand, mft::msg::OperatorCommandPubSubType>(oc) == oc));
  mft::msg::Reference ref;
  ref.stance_leg(-1);
  ref.foot_acc()[3] = 7.0;
  ref.base_x()[0] = 0.03;
  ref.hold_base_x(true);
  EXPECT_TRUE((roundTrip<mft::msg::Reference, mft::msg::ReferencePubSubType>(ref) == ref));
  mft::msg::WbcDiagnostics d;
  d.status(3);
  d.task_error()[5] = 1e-3;
  EXPECT_TRUE((roundTrip<mft::msg::WbcDiagnostics, mft::msg::WbcDiagnosticsPubSubType>(d) == d));
  mft::msg::Disturbance dist;
  dist.impulse(7.1);
  dist.trigger(mft::msg::TRIGGER_AT_NEXT_LIFTOFF);
  EXPECT_TRUE((roundTrip<mft::msg::Disturbance, mft::msg::DisturbancePubSubType>(dist) == dist));
  mft::msg::CommandVerdict verdict;
  verdict.seq(0x1234567890abcdefULL);
  verdict.source(mft::msg::COMMAND_SOURCE_SIMULATOR);
  verdict.verdict(mft::msg::VERDICT_APPLIED);
  verdict.accepted(true);
  verdict.tick(3085);
  const char reason[] = "push of 3.000 N s applied at t = 3.0850 s (tick 3085)";
  std::copy(std::begin(reason), std::end(reason), verdict.reason().begin());
  const auto back = roundTrip<mft::msg::CommandVerdict, mft::msg::CommandVerdictPubSubType>(verdict);
  EXPECT_TRUE(back == verdict);
  EXPECT_STREQ(back.reason().data(), reason);
  mft::msg::ConfigChange change;  // live tuning (docs/guide/live-tuning.md)
  change.seq(42);
  change.target(mft::msg::CONFIG_TARGET_PLANNER);
  const char key[] = "foot_placement.k_v", value[] = "0.145";
  std::copy(std::begin(key), std::end(key), change.key().begin());
  std::copy(std::begin(value), std::end(value), change.value().begin());
  change.at_s(12.5);
  change.applied(true);
  change.tick(12500);
  change.number({0.145, 0.0});
  change.count(1);
  const auto change_back = roundTrip<mft::msg::ConfigChange, mft::msg::ConfigChangePubSubType>(change);
  EXPECT_TRUE(change_back == change);
  EXPECT_STREQ(change_back.key().data(), key);
}
