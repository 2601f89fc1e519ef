// Safety stage: NaN input gives damping (never NaN torques), the hold-then-damp sequence, counters, latching.
#include <gtest/gtest.h>

#include <limits>

#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

using test::makeState;
using test::robot;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(SafetyStage, HoldsThenDampsAndCounts) {
  model::VectorA tau_max = model::VectorA::Constant(50.0);
  SafetyStage s(3, 2.0, tau_max, false);
  model::VectorQ qd = model::VectorQ::Zero();
  qd[model::kActuatedIndex[0]] = 1.0;
  qd[model::kActuatedIndex[1]] = -100.0;  // damping torque saturates at tau_max
  model::ActuatorCommand good;
  good.tick = 1;
  good.tau << 1, 2, 3, 4;
  EXPECT_EQ(s.accept(good, qd).tau, good.tau);
  for (int k = 0; k < 3; ++k) {
    const model::ActuatorCommand c = s.reject(SafetyEvent::SolverFailure, 2 + k, qd);
    EXPECT_EQ(s.mode(), SafetyMode::Holding);
    EXPECT_EQ(c.mode, model::CommandMode::Normal);
    EXPECT_EQ(c.tau, good.tau);
    EXPECT_EQ(c.tick, 2u + k);
  }
  const model::ActuatorCommand d = s.reject(SafetyEvent::NonFiniteInput, 5, qd);
  EXPECT_EQ(s.mode(), SafetyMode::Damping);
  EXPECT_EQ(d.mode, model::CommandMode::Damping);
  EXPECT_DOUBLE_EQ(d.tau[0], -2.0);
  EXPECT_DOUBLE_EQ(d.tau[1], 50.0);
  EXPECT_EQ(s.counters().events, 4u);
  EXPECT_EQ(s.counters().solver_failure, 3u);
  EXPECT_EQ(s.counters().nonfinite_input, 1u);
  EXPECT_EQ(s.counters().hold_ticks, 3u);
  EXPECT_EQ(s.counters().damping_ticks, 1u);
  EXPECT_EQ(s.counters().damping_entries, 1u);
  // Recovery without latching.
  EXPECT_EQ(s.accept(good, qd).mode, model::CommandMode::Normal);
  EXPECT_EQ(s.mode(), SafetyMode::Normal);
  EXPECT_EQ(s.consecutiveFailures(), 0);
}

TEST(SafetyStage, LatchedDampingStaysUntilReset) {
  SafetyStage s(0, 1.0, model::VectorA::Constant(50.0), true);
  model::ActuatorCommand good;
  s.accept(good, model::VectorQ::Zero());
  EXPECT_EQ(s.reject(SafetyEvent::SolverFailure, 1, model::VectorQ::Zero()).mode, model::CommandMode::Damping);
  EXPECT_EQ(s.accept(good, model::VectorQ::Zero()).mode, model::CommandMode::Damping);
  EXPECT_EQ(s.counters().damping_ticks, 2u);
  s.reset();
  EXPECT_EQ(s.accept(good, model::VectorQ::Zero()).mode, model::CommandMode::Normal);
}

TEST(SafetyStage, NoGoodCommandYetMeansDampingAtOnce) {
  SafetyStage s(5, 1.0, model::VectorA::Constant(50.0), false);
  model::VectorQ qd = model::VectorQ::Constant(kNaN);
  const model::ActuatorCommand c = s.reject(SafetyEvent::NonFiniteInput, 0, qd);
  EXPECT_EQ(c.mode, model::CommandMode::Damping);
  EXPECT_TRUE(c.tau.allFinite());
  EXPECT_EQ(c.tau, model::VectorA::Zero());
}

class WbcSafety : public ::testing::Test {
 protected:
  WbcPolytope poly = test::testPolytope();
  model::RobotStateEstimate st = makeState({});
  WbcReference ref = test::holdReference(st);
};

TEST_F(WbcSafety, NanStateGivesDampingNotNanTorques) {
  WholeBodyController wbc(robot(), test::projectConfig(WbcVariant::Mft), poly);
  for (int which = 0; which < 3; ++which) {
    model::RobotStateEstimate bad = st;
    WbcReference bad_ref = ref;
    if (which == 0) bad.q[5] = kNaN;
    if (which == 1) bad.qd[model::kActuatedIndex[2]] = std::numeric_limits<double>::infinity();
    if (which == 2) bad_ref.foot_pos[1] = kNaN;
    WbcDiagnostics diag;
    const model::ActuatorCommand c = wbc.update(bad, bad_ref, &diag);  // no good command yet: damping at once
    EXPECT_EQ(c.mode, model::CommandMode::Damping) << which;
    EXPECT_TRUE(c.tau.allFinite()) << which;
    EXPECT_EQ(diag.safety_event, SafetyEvent::NonFiniteInput);
    EXPECT_FALSE(diag.qp_attempted);
    EXPECT_EQ(diag.safety.nonfinite_input, static_cast<std::uint64_t>(which + 1));
  }
}

TEST_F(WbcSafety, HoldThenDampSequenceAndRecovery) {
  WbcConfig cfg = test::projectConfig(WbcVariant::Mft);
  cfg.safety.hold_ticks = 3;
  WholeBodyController wbc(robot(), cfg, poly);
  WbcDiagnostics diag;
  const model::ActuatorCommand good = wbc.update(st, ref, &diag);
  ASSERT_EQ(good.mode, model::CommandMode::Normal);
  model::RobotStateEstimate bad = st;
  bad.q[1] = kNaN;
  for (int k = 1; k <= 6; ++k) {
    bad.tick = k;
    const model::ActuatorCommand c = wbc.update(bad, ref, &diag);
    ASSERT_TRUE(c.tau.allFinite());
    EXPECT_EQ(c.tick, static_cast<std::uint64_t>(k));
    if (k <= 3) {
      EXPECT_EQ(c.mode, model::CommandMode::Normal) << k;
      EXPECT_EQ(c.tau, good.tau) << k;
      EXPECT_EQ(diag.safety_mode, SafetyMode::Holding);
    } else {
      EXPECT_EQ(c.mode, model::CommandMode::Damping) << k;
      EXPECT_EQ(diag.safety_mode, SafetyMode::Damping);
    }
    EXPECT_EQ(diag.safety.events, static_cast<std::uint64_t>(k));
  }
  EXPECT_EQ(diag.safety.hold_ticks, 3u);
  EXPECT_EQ(diag.safety.damping_ticks, 3u);
  EXPECT_EQ(diag.safety.damping_entries, 1u);
  // A good tick resumes normal control (no latch configured) and keeps the counts.
  const model::ActuatorCommand again = wbc.update(st, ref, &diag);
  EXPECT_EQ(again.mode, model::CommandMode::Normal);
  EXPECT_EQ(diag.safety_mode, SafetyMode::Normal);
  EXPECT_EQ(diag.safety.events, 6u);
}

TEST_F(WbcSafety, SolverFailureIsCaughtAndCounted) {
  // A qdd box far too small for free fall: with both feet scheduled in swing the QP is infeasible.
  WbcConfig cfg = test::projectConfig(WbcVariant::Mft);
  cfg.limits.qdd_base_max = Eigen::Vector3d::Constant(1e-3);
  cfg.limits.qdd_joint_max_radps2 = 1e-3;
  cfg.safety.hold_ticks = 1;
  WholeBodyController wbc(robot(), cfg, poly);
  WbcDiagnostics diag;
  ASSERT_EQ(wbc.update(st, ref, &diag).mode, model::CommandMode::Normal);  // standing is feasible
  WbcReference airborne = ref;
  airborne.foot_in_stance = {false, false};
  const model::ActuatorCommand held = wbc.update(st, airborne, &diag);
  EXPECT_NE(diag.status, qp::QpStatus::Optimal);
  EXPECT_TRUE(diag.qp_attempted);
  EXPECT_EQ(diag.safety_event, SafetyEvent::SolverFailure);
  EXPECT_EQ(held.mode, model::CommandMode::Normal);
  EXPECT_EQ(wbc.update(st, airborne, &diag).mode, model::CommandMode::Damping);
  EXPECT_EQ(diag.safety.solver_failure, 2u);
  EXPECT_EQ(diag.safety.events, 2u);
}

}  // namespace
}  // namespace mft::wbc
