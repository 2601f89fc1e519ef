// Problem 1 solutions checked against independent computations from the model: floating-base dynamics
// (eq. 3 / 16a), loop closure, friction pyramids, torque limits, and eq. 1 forward dynamics reproducing qdd.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

using test::makeState;
using test::robot;

struct Case {
  const char* name;
  test::StateSpec spec;
  bool right_stance, left_stance;
};

std::vector<Case> cases() {
  std::vector<Case> c;
  c.push_back({"standing", {}, true, true});
  test::StateSpec moving;
  moving.base_vel = {0.1, -0.05, 0.2};
  moving.right_foot_vel = {-0.1, 0.05};
  moving.left_foot_vel = {-0.1, 0.02};
  c.push_back({"standing_moving", moving, true, true});
  test::StateSpec single = moving;
  single.left_foot = {0.0, -0.35};
  single.left_foot_vel = {0.3, 0.2};
  c.push_back({"right_stance_left_swing", single, true, false});
  test::StateSpec single_r = moving;
  single_r.right_foot = {0.1, -0.36};
  c.push_back({"left_stance_right_swing", single_r, false, true});
  return c;
}

class WbcPhysics : public ::testing::TestWithParam<WbcVariant> {};

TEST_P(WbcPhysics, SolutionSatisfiesDynamicsClosureFrictionTorqueLimits) {
  const WbcPolytope poly = test::testPolytope();
  const WbcConfig cfg = test::projectConfig(GetParam());
  WholeBodyController wbc(robot(), cfg, poly);
  const model::PlanarModel m = model::buildBipedModel(robot());
  const double tau_max = robot().actuator.outputPeakTorque();
  const double mu = cfg.contact.friction_fraction * robot().friction_coefficient;

  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const model::RobotStateEstimate st = makeState(c.spec, 7);
    WbcReference ref = test::holdReference(st, c.right_stance, c.left_stance);
    ref.base_z.pos += 0.01;  // something to track
    ref.foot_acc[0] = c.right_stance ? 0.0 : 1.0;
    WbcDiagnostics diag;
    // Table I's force-rate weight (5e-2) prices f_c against the previous tick's f_c: a fresh controller starts
    // from zero force, so the first answer carries only a fraction of the weight. 300 ticks on the same state
    // let f_c settle where w_fc alone puts it: m (g + a) / (1 + w_fc m^2 / w_z) (about 2/3 of the weight).
    for (int k = 0; k < 300; ++k) wbc.update(st, ref, &diag);
    const model::ActuatorCommand cmd = wbc.update(st, ref, &diag);
    ASSERT_EQ(diag.status, qp::QpStatus::Optimal);
    ASSERT_EQ(cmd.mode, model::CommandMode::Normal);
    ASSERT_EQ(diag.safety_event, SafetyEvent::None);
    EXPECT_EQ(cmd.tick, 7u);
    EXPECT_FALSE(diag.torque_clamped);
    const model::VectorQ& qdd = diag.qdd;
    const model::VectorC& fc = diag.f_c;

    // Independent model evaluation at the same state.
    model::ModelData d;
    model::updateModel(m, st.q, st.qd, &d);
    model::ClosureProjection p;
    model::closureProjection(d, &p);

    // 16a: S_f (M qdd + N_h' h) = S_f N_h' J_c' f_c.
    const model::VectorQ lhs = d.M * qdd + p.N_h.transpose() * d.h;
    const model::VectorQ rhs = p.N_h.transpose() * d.Jc.transpose() * fc;
    EXPECT_LT((lhs - rhs).head<3>().cwiseAbs().maxCoeff(), 1e-7) << (lhs - rhs).head<3>().transpose();
    // Loop closure at the acceleration level.
    EXPECT_LT((d.Jh * qdd + d.Jh_dot_qd).cwiseAbs().maxCoeff(), 1e-8);
    // Friction pyramid and normal force bounds; a swing foot carries nothing.
    const bool stance[2] = {c.right_stance, c.left_stance};
    for (int foot = 0; foot < 2; ++foot) {
      const double fx = fc[2 * foot], fz = fc[2 * foot + 1];
      EXPECT_GE(fz, -1e-9);
      EXPECT_LE(std::abs(fx), mu * fz + 1e-7);
      if (stance[foot]) EXPECT_LE(fz, cfg.contact.normal_force_max_N + 1e-7);
      else EXPECT_NEAR(fz, 0.0, 1e-12);
    }
    // Torque limits, and the command is eq. 7 of the model (not clamped).
    const model::VectorA tau7 = model::inverseDynamicsActuated(d, p, qdd, st.qd, fc);
    EXPECT_LT((cmd.tau - tau7).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LE(cmd.tau.cwiseAbs().maxCoeff(), tau_max + 1e-9);
    // qdd box.
    for (int i = 0; i < model::kNq; ++i)
      EXPECT_LE(std::abs(qdd[i]), (i < 3 ? cfg.limits.qdd_base_max[i] : cfg.limits.qdd_joint_max_radps2) + 1e-7);
    // Eq. 1 forward dynamics with the WBC torques and contact forces reproduces the WBC accelerations.
    model::VectorQ qdd_fd;
    model::VectorH f_h;
    model::constrainedForwardDynamics(d, cmd.tau, fc, &qdd_fd, &f_h);
    EXPECT_LT((qdd_fd - qdd).cwiseAbs().maxCoeff(), 1e-6) << "fd " << qdd_fd.transpose() << "\nqp " << qdd.transpose();
    // The robot is held up: most of the weight is carried (Table I's w_fc takes a little).
    EXPECT_GT(fc[1] + fc[3], 0.5 * robot().totalMass() * robot().gravity_mps2);
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, WbcPhysics, ::testing::Values(WbcVariant::Mft, WbcVariant::Sa, WbcVariant::None),
                         [](const auto& param_info) { return std::string(toString(param_info.param)); });

TEST(WbcDynamicsTerms, AffineTorqueMapEqualsInverseDynamics) {
  test::StateSpec s;
  s.base_vel = {0.2, 0.1, -0.3};
  s.right_foot_vel = {0.2, -0.1};
  s.left_foot_vel = {-0.3, 0.4};
  const model::RobotStateEstimate st = makeState(s);
  const model::PlanarModel m = model::buildBipedModel(robot());
  model::ModelData d;
  model::updateModel(m, st.q, st.qd, &d);
  model::ClosureProjection p;
  model::closureProjection(d, &p);
  DynamicsTerms t;
  ASSERT_TRUE(computeDynamicsTerms(d, p, &t));
  for (int k = 0; k < 5; ++k) {
    const model::VectorQ qdd = model::VectorQ::Random() * 5.0;
    const model::VectorC fc = model::VectorC::Random() * 100.0;
    const model::VectorA a = model::actuatedTorque(t.torque, qdd, fc);
    // Independent of the map's factorisation: eq. 7 as generalized forces projected by N_h', the actuated rows
    // and columns picked, and the 4x4 system solved by pivoted LU.
    const model::MatrixQ NhT = p.N_h.transpose();
    const model::VectorQ generalized = d.M * qdd + NhT * d.h + d.Jh.transpose() * (p.Lambda_h * d.Jh_dot_qd) -
                                       NhT * (d.Jc.transpose() * fc);
    Eigen::Matrix<double, model::kNa, model::kNa> selection;
    model::VectorA selected;
    for (int r = 0; r < model::kNa; ++r) {
      selected(r) = generalized(model::kActuatedIndex[r]);
      for (int c = 0; c < model::kNa; ++c) selection(r, c) = NhT(model::kActuatedIndex[r], model::kActuatedIndex[c]);
    }
    const model::VectorA b = selection.partialPivLu().solve(selected);
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + b.cwiseAbs().maxCoeff()));
    // The one-call form is the same map evaluated.
    EXPECT_EQ(model::inverseDynamicsActuated(d, p, qdd, st.qd, fc), a);
  }
  // At a closed loop S_f N_h' = S_f (J_h has no base columns), so 16a is the plain floating-base row of eq. 1.
  EXPECT_LT((t.base_NhT - Eigen::Matrix<double, 3, model::kNq>::Identity()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(WbcProblem, LayoutAndStructureMatchTheSharedFormat) {
  const WbcPolytope poly = test::testPolytope();
  WholeBodyController wbc(robot(), test::projectConfig(WbcVariant::Mft), poly);
  const model::RobotStateEstimate st = makeState({});
  WbcDiagnostics diag;
  wbc.update(st, test::holdReference(st), &diag);
  const qp::QpProblem& p = wbc.lastProblem();
  EXPECT_EQ(p.n, 27);
  EXPECT_EQ(p.neq, 7);
  EXPECT_EQ(p.nin, 4 + 4 + 12);
  EXPECT_EQ(p.dense_block, 11);
  // H symmetric positive definite.
  EXPECT_LT((p.H - p.H.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(p.H);
  EXPECT_GT(es.eigenvalues().minCoeff(), 1e-4);
  const Formulation& f = wbc.formulation();
  EXPECT_EQ(f.constraints[findConstraint(f, "in_mft")].row_offset, 8);
  EXPECT_EQ(diag.num_tasks, static_cast<int>(wbc.taskNames().size()));

  WholeBodyController sa(robot(), test::projectConfig(WbcVariant::Sa), nullptr);
  sa.update(st, test::holdReference(st), &diag);
  EXPECT_EQ(sa.lastProblem().nin, 4 + 4 + 4);
  EXPECT_EQ(sa.lastProblem().lb.tail<12>().cwiseAbs().maxCoeff(), 0.0);  // eps fixed to 0
  EXPECT_EQ(sa.lastProblem().ub.tail<12>().cwiseAbs().maxCoeff(), 0.0);
  WholeBodyController none(robot(), test::projectConfig(WbcVariant::None), nullptr);
  none.update(st, test::holdReference(st), &diag);
  EXPECT_EQ(none.lastProblem().nin, 8);
  EXPECT_TRUE(std::isnan(diag.mft_violation));  // no polytope given
}

TEST(WbcProblem, MftNeedsAPolytope) {
  EXPECT_THROW(WholeBodyController(robot(), test::projectConfig(WbcVariant::Mft), nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace mft::wbc
