// Problem 1 one equation at a time (wbc/wbc_equations.hpp), each checked against a computation of its own: closed
// forms written out here, finite differences, forward dynamics (6) solved by its Schur complement, and the QP's
// H and g against a least-squares problem stacked here from the model. Paper numbers as published (docs/reference/theory.md).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "model/mft_polytope.hpp"
#include "wbc/wbc_equations.hpp"
#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

using test::makeState;
using test::robot;
constexpr double kInf = std::numeric_limits<double>::infinity();

double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
}

// A moving closed-loop state (both feet down, velocities consistent with the closure).
model::RobotStateEstimate movingState() {
  test::StateSpec s;
  s.base_vel = {0.15, -0.05, 0.2};
  s.right_foot_vel = {-0.1, 0.05};
  s.left_foot_vel = {0.2, 0.1};
  s.left_foot = {-0.03, -0.37};
  return makeState(s, 3);
}

// ---------------------------------------------------------------------------------------------------------------
// (17) PD task acceleration.

TEST(WbcEquations, PdAccelerationIsTheClosedFormAndDrivesTheErrorLikeACriticallyDampedSpring) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-3.0, 3.0), k(0.0, 500.0);
  for (int n = 0; n < 200; ++n) {
    const Setpoint1 ref{u(rng), u(rng), u(rng)};
    const double pos = u(rng), vel = u(rng);
    const PdGains1 g{k(rng), k(rng) / 10.0};
    const double expected = ref.acc + g.kp * (ref.pos - pos) + g.kd * (ref.vel - vel);
    EXPECT_NEAR(pdAcceleration(ref, pos, vel, g), expected, 1e-12 * (1.0 + std::abs(expected)));
  }
  // Table I's base gains (kp = 400, kd = 40: omega = 20 rad/s, critically damped) on a double integrator with a
  // fixed reference: the error follows e0 (1 + omega t) exp(-omega t). Semi-implicit Euler at 1e-6 s for 0.3 s
  // (its error, about h omega e0 = 4e-7 m, is below the tolerance).
  const PdGains1 g{400.0, 40.0};
  const Setpoint1 ref{0.42, 0.0, 0.0};
  double x = 0.40, v = 0.0;
  const double h = 1e-6;
  for (int i = 1; i <= 300000; ++i) {
    v += h * pdAcceleration(ref, x, v, g);
    x += h * v;
    if (i % 50000 == 0) {
      const double t = i * h;
      EXPECT_NEAR(ref.pos - x, 0.02 * (1.0 + 20.0 * t) * std::exp(-20.0 * t), 2e-6) << t;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// (15a)-(15c): the cost. The controller's H and g against a least-squares problem stacked here row by row.

struct LsRow {
  Eigen::Matrix<double, kNx, 1> a = Eigen::Matrix<double, kNx, 1>::Zero();
  double target = 0.0;
  double weight = 0.0;
};

TEST(WbcEquations, TaskHessianAndGradientAreThoseOfTheStackedLeastSquaresProblem) {
  const WbcConfig cfg = test::projectConfig(WbcVariant::Mft);
  WholeBodyController wbc(robot(), cfg, test::testPolytope());
  const model::RobotStateEstimate st = movingState();
  WbcReference ref = test::holdReference(st, true, false);  // right stance, left swing
  ref.base_z = {st.q[model::kBaseZ] + 0.01, 0.02, 0.3};
  ref.base_pitch = {0.05, -0.1, 0.2};
  ref.foot_pos[2] += 0.02;
  ref.foot_pos[3] += 0.03;
  ref.foot_vel << 0.0, 0.0, 0.3, 0.1;
  ref.foot_acc << 0.0, 0.0, 1.0, -2.0;
  WbcDiagnostics diag;
  wbc.update(st, ref, &diag);  // a fresh controller: f_c^- is the start value, all weight on the right foot
  const qp::QpProblem& p = wbc.lastProblem();

  const model::PlanarModel m = model::buildBipedModel(robot());
  model::ModelData d;
  model::updateModel(m, st.q, st.qd, &d);
  const WbcWeights& w = cfg.weights;
  const WbcGains& k = cfg.gains;
  std::vector<LsRow> rows;
  auto coordinateRow = [&](int index, const Setpoint1& r, const PdGains1& gains, double weight) {
    LsRow row;
    row.a[index] = 1.0;
    row.target = r.acc + gains.kp * (r.pos - st.q[index]) + gains.kd * (r.vel - st.qd[index]);
    row.weight = weight;
    rows.push_back(row);
  };
  coordinateRow(model::kBaseZ, ref.base_z, k.base_z, w.base_z);
  coordinateRow(model::kBasePitch, ref.base_pitch, k.base_pitch, w.base_pitch);
  for (int leg = 0; leg < 2; ++leg) {
    const bool stance = ref.foot_in_stance[leg];
    const PdGains2& gains = stance ? k.support_foot : k.swing_foot;
    for (int axis = 0; axis < 2; ++axis) {
      const int r = 2 * leg + axis;
      LsRow row;
      row.a.head<kNqdd>() = d.Jc.row(r).transpose();
      row.target = ref.foot_acc[r] + gains.kp[axis] * (ref.foot_pos[r] - d.foot_pos[r]) +
                   gains.kd[axis] * (ref.foot_vel[r] - d.foot_vel[r]) - d.Jc_dot_qd[r];
      row.weight = stance ? w.support_foot : w.swing_foot;
      rows.push_back(row);
    }
  }
  const double weight_N = robot().totalMass() * m.gravity;
  const double fc_prev[kNfc] = {0.0, weight_N, 0.0, 0.0};
  for (int i = 0; i < kNfc; ++i) {
    LsRow force, rate;
    force.a[kNqdd + i] = rate.a[kNqdd + i] = 1.0;
    force.weight = w.contact_force;
    rate.weight = w.contact_force_rate;
    rate.target = fc_prev[i];
    rows.push_back(force);
    rows.push_back(rate);
  }
  for (int i = 0; i < kNeps; ++i) {
    LsRow slack;
    slack.a[kNqdd + kNfc + i] = 1.0;
    slack.weight = w.slack;
    rows.push_back(slack);
  }
  for (int i = 0; i < kNqdd; ++i) {
    LsRow reg;
    reg.a[i] = 1.0;
    reg.weight = w.qdd_regularization;
    rows.push_back(reg);
  }
  // (base x has weight 0: the left foot swings.)
  Eigen::MatrixXd A(rows.size(), kNx);
  Eigen::VectorXd b(rows.size()), W(rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    A.row(r) = rows[r].a.transpose();
    b[r] = rows[r].target;
    W[r] = rows[r].weight;
  }
  // sum_r w_r (a_r' x - b_r)^2 = 1/2 x' H x + g' x + const: H = 2 A' W A, g = -2 A' W b.
  const Eigen::MatrixXd H = 2.0 * A.transpose() * W.asDiagonal() * A;
  const Eigen::VectorXd g = -2.0 * A.transpose() * W.asDiagonal() * b;
  EXPECT_LT(relativeError(p.H, H), 1e-12);
  EXPECT_LT(relativeError(p.g, g), 1e-12);
  // The convention itself, on random x: the quadratic form equals the weighted sum of squared residuals.
  std::mt19937 rng(43);
  std::normal_distribution<double> n(0.0, 5.0);
  for (int t = 0; t < 20; ++t) {
    Eigen::VectorXd x(kNx);
    for (int i = 0; i < kNx; ++i) x[i] = n(rng);
    const double cost = (W.array() * (A * x - b).array().square()).sum();
    const double quadratic = 0.5 * x.dot(p.H * x) + p.g.dot(x) + (W.array() * b.array().square()).sum();
    EXPECT_NEAR(quadratic, cost, 1e-9 * (1.0 + cost));
  }
}

TEST(WbcEquations, InitialPreviousContactForceSharesTheWeightAmongTheStanceFeet) {
  const model::VectorC both = initialPreviousContactForce(300.0, {true, true});
  const model::VectorC right = initialPreviousContactForce(300.0, {true, false});
  const model::VectorC left = initialPreviousContactForce(300.0, {false, true});
  EXPECT_EQ(both, model::VectorC(0.0, 150.0, 0.0, 150.0));
  EXPECT_EQ(right, model::VectorC(0.0, 300.0, 0.0, 0.0));
  EXPECT_EQ(left, model::VectorC(0.0, 0.0, 0.0, 300.0));
}

// (15b): the force-rate term prices f_c against f_c^-, the contact forces of the last solved tick; a failed tick
// leaves f_c^- alone, resetSafety() starts again from the weight. Read off the QP's g: the f_c part is
// -2 w_dfc f_c^- (||f_c||^2 has a zero target), the f_c block of H is 2 (w_fc + w_dfc) I.
TEST(WbcEquations, ForceRateTaskFollowsTheLastSolvedContactForces) {
  const WbcConfig cfg = test::projectConfig(WbcVariant::Mft);
  WholeBodyController wbc(robot(), cfg, test::testPolytope());
  const double w_fc = cfg.weights.contact_force, w_dfc = cfg.weights.contact_force_rate;
  const double weight_N = robot().totalMass() * model::buildBipedModel(robot()).gravity;
  const model::RobotStateEstimate st = movingState();
  WbcReference ref = test::holdReference(st);
  ref.base_z.pos += 0.01;
  auto gradientFc = [&] { return Eigen::Vector4d(wbc.lastProblem().g.segment<kNfc>(kNqdd)); };
  auto expectPrevious = [&](const model::VectorC& fc_prev, const char* what) {
    SCOPED_TRACE(what);
    EXPECT_LT((gradientFc() + 2.0 * w_dfc * fc_prev).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + fc_prev.norm()));
  };

  WbcDiagnostics d1, d2, d3, d4;
  wbc.update(st, ref, &d1);
  expectPrevious(model::VectorC(0.0, weight_N / 2, 0.0, weight_N / 2), "first tick: the weight on both feet");
  const Eigen::Matrix4d Hfc = wbc.lastProblem().H.block<kNfc, kNfc>(kNqdd, kNqdd);
  EXPECT_LT((Hfc - 2.0 * (w_fc + w_dfc) * Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  ASSERT_EQ(d1.status, qp::QpStatus::Optimal);

  wbc.update(st, ref, &d2);
  expectPrevious(d1.f_c, "second tick: the first tick's solution");
  ASSERT_EQ(d2.status, qp::QpStatus::Optimal);
  EXPECT_GT((d2.f_c - d1.f_c).norm(), 1e-6);  // the forces move, so the bookkeeping is visible

  model::RobotStateEstimate bad = st;
  bad.q[4] = std::numeric_limits<double>::quiet_NaN();
  wbc.update(bad, ref, &d3);  // fails before the QP: f_c^- stays d2.f_c
  EXPECT_NE(d3.safety_event, SafetyEvent::None);
  wbc.update(st, ref, &d4);
  expectPrevious(d2.f_c, "after a failed tick: the last solved tick's forces");

  wbc.resetSafety();
  wbc.update(st, test::holdReference(st, false, true), &d4);
  expectPrevious(model::VectorC(0.0, 0.0, 0.0, weight_N), "after resetSafety: the weight on the left stance foot");
}

// (15c): ||eps||^2, identity with a zero target; in the QP a diagonal eps block 2 w_eps I, no gradient, no coupling.
TEST(WbcEquations, SlackTaskIsTheIdentityWithAZeroTarget) {
  TaskMatrix A;
  TaskVector b;
  slackTaskRows(&A, &b);
  ASSERT_EQ(A.rows(), kNeps);
  ASSERT_EQ(A.cols(), kNeps);
  EXPECT_EQ(A, (Eigen::Matrix<double, kNeps, kNeps>::Identity()));
  EXPECT_EQ(b.size(), kNeps);
  EXPECT_EQ(b.cwiseAbs().maxCoeff(), 0.0);

  const WbcConfig cfg = test::projectConfig(WbcVariant::Mft);
  WholeBodyController wbc(robot(), cfg, test::testPolytope());
  const model::RobotStateEstimate st = movingState();
  wbc.update(st, test::holdReference(st), nullptr);
  const qp::QpProblem& p = wbc.lastProblem();
  const int e = kNqdd + kNfc;
  const Eigen::MatrixXd H_eps = p.H.block(e, e, kNeps, kNeps);
  EXPECT_EQ(H_eps, (2.0 * cfg.weights.slack * Eigen::MatrixXd::Identity(kNeps, kNeps)));
  EXPECT_EQ(p.g.segment(e, kNeps).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(p.H.block(e, 0, kNeps, e).cwiseAbs().maxCoeff(), 0.0);
}

// (15a) row builders: a unit row for a base coordinate, the foot's J_c rows with the J_c-dot qd offset.
TEST(WbcEquations, TaskRowBuildersAreTheUnitRowAndTheContactJacobianRows) {
  TaskMatrix A;
  TaskVector b;
  coordinateTaskRows(model::kBasePitch, 1.5, &A, &b);
  ASSERT_EQ(A.rows(), 1);
  ASSERT_EQ(A.cols(), kNqdd);
  for (int j = 0; j < kNqdd; ++j) EXPECT_EQ(A(0, j), j == model::kBasePitch ? 1.0 : 0.0);
  EXPECT_EQ(b(0), 1.5);

  const model::RobotStateEstimate st = movingState();
  model::ModelData d;
  model::updateModel(model::buildBipedModel(robot()), st.q, st.qd, &d);
  footTaskRows(d.Jc, d.Jc_dot_qd, model::kLeftLeg, Eigen::Vector2d(0.7, -0.2), &A, &b);
  ASSERT_EQ(A.rows(), 2);
  EXPECT_EQ(A, d.Jc.bottomRows<2>());
  EXPECT_EQ(b(0), 0.7 - d.Jc_dot_qd[2]);
  EXPECT_EQ(b(1), -0.2 - d.Jc_dot_qd[3]);
}

// ---------------------------------------------------------------------------------------------------------------
// (8) = (16a), (16b), (16c), (16d).

struct Dynamics {
  model::ModelData data;
  model::ClosureProjection proj;
  DynamicsTerms terms;
};
Dynamics dynamicsAt(const model::RobotStateEstimate& st) {
  Dynamics d;
  model::updateModel(model::buildBipedModel(robot()), st.q, st.qd, &d.data);
  model::closureProjection(d.data, &d.proj);
  EXPECT_TRUE(computeDynamicsTerms(d.data, d.proj, &d.terms));
  return d;
}

// x = [qdd | f_c | eps] from the forward dynamics (6) of random torques and contact forces (Schur complement,
// independent of the projection the rows use).
struct ForwardSample {
  model::VectorA tau;
  Eigen::Matrix<double, kNx, 1> x;
};
ForwardSample forwardSample(const model::ModelData& data, std::mt19937& rng) {
  std::uniform_real_distribution<double> t(-40.0, 40.0), fx(-60.0, 60.0), fz(0.0, 250.0), e(-1.0, 1.0);
  ForwardSample s;
  for (int i = 0; i < model::kNa; ++i) s.tau[i] = t(rng);
  const model::VectorC fc(fx(rng), fz(rng), fx(rng), fz(rng));
  model::VectorQ qdd;
  model::constrainedForwardDynamics(data, s.tau, fc, &qdd, nullptr);
  s.x << qdd, fc, Eigen::Matrix<double, kNeps, 1>::Zero();
  for (int i = 0; i < kNeps; ++i) s.x[kNqdd + kNfc + i] = e(rng);  // eps must not matter
  return s;
}

TEST(WbcEquations, BaseDynamicsRowsHoldOnForwardDynamicsSolutions) {
  std::mt19937 rng(47);
  const Dynamics d = dynamicsAt(movingState());
  ConstraintMatrix A;
  ConstraintVector rhs;
  baseDynamicsRows(d.data.M, d.data.h, d.data.Jc, d.terms.base_NhT, &A, &rhs);
  ASSERT_EQ(A.rows(), 3);
  ASSERT_EQ(rhs.size(), 3);
  EXPECT_EQ(A.rightCols<kNeps>().cwiseAbs().maxCoeff(), 0.0);  // eps does not enter (8)
  for (int n = 0; n < 50; ++n) {
    const ForwardSample s = forwardSample(d.data, rng);
    const Eigen::Vector3d residual = A * s.x - rhs;
    EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-9 * (1.0 + rhs.cwiseAbs().maxCoeff() + 300.0)) << residual.transpose();
  }
  // And the loop closure rows (second block row of (6)) on the same solutions.
  loopClosureRows(d.data.Jh, d.data.Jh_dot_qd, &A, &rhs);
  for (int n = 0; n < 20; ++n) {
    const ForwardSample s = forwardSample(d.data, rng);
    EXPECT_LT((A * s.x - rhs).cwiseAbs().maxCoeff(), 1e-10);
  }
}

TEST(WbcEquations, FrictionRowsAndForceBoundsAreThePyramid) {
  const double mu = 0.6;
  ConstraintMatrix A;
  ConstraintVector lo, hi;
  frictionPyramidRows(mu, &A, &lo, &hi);
  ASSERT_EQ(A.rows(), 4);
  for (int r = 0; r < 4; ++r) {
    const int foot = r / 2;
    EXPECT_EQ(lo(r), -kInf);
    EXPECT_EQ(hi(r), 0.0);
    for (int c = 0; c < kNx; ++c) {
      double expected = 0.0;
      if (c == kNqdd + 2 * foot) expected = r % 2 == 0 ? 1.0 : -1.0;
      if (c == kNqdd + 2 * foot + 1) expected = -mu;
      EXPECT_EQ(A(r, c), expected) << r << " " << c;
    }
  }
  // Points inside the cone |f_x| <= mu f_z satisfy every row, points outside violate one.
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> fx(-100.0, 100.0), fz(0.0, 100.0);
  int inside = 0, outside = 0;
  for (int n = 0; n < 2000; ++n) {
    Eigen::Matrix<double, kNx, 1> x = Eigen::Matrix<double, kNx, 1>::Zero();
    x.segment<kNfc>(kNqdd) << fx(rng), fz(rng), fx(rng), fz(rng);
    const bool in_cone = std::abs(x[kNqdd]) <= mu * x[kNqdd + 1] && std::abs(x[kNqdd + 2]) <= mu * x[kNqdd + 3];
    const bool rows_hold = ((A * x).array() <= hi.array()).all();
    EXPECT_EQ(rows_hold, in_cone);
    (in_cone ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 100);

  VariableBounds bounds;
  contactForceBounds({true, false}, 900.0, &bounds);
  EXPECT_EQ(bounds.lb.segment<kNfc>(kNqdd), Eigen::Vector4d(-kInf, 0.0, -kInf, 0.0));
  EXPECT_EQ(bounds.ub.segment<kNfc>(kNqdd), Eigen::Vector4d(kInf, 900.0, kInf, 0.0));  // a swing foot carries nothing
}

// (16c): A x + tau_0 is the actuated torque; checked with the torques that produced x through forward dynamics.
TEST(WbcEquations, TorqueRowsAreTheInverseDynamicsTorqueAgainstItsLimits) {
  std::mt19937 rng(59);
  const Dynamics d = dynamicsAt(movingState());
  const model::VectorA tau_max(30.0, 31.0, 32.0, 33.0);
  ConstraintMatrix A;
  ConstraintVector lo, hi;
  torqueLimitRows(d.terms.torque, tau_max, &A, &lo, &hi);
  ASSERT_EQ(A.rows(), model::kNa);
  EXPECT_EQ(A.rightCols<kNeps>().cwiseAbs().maxCoeff(), 0.0);
  for (int n = 0; n < 50; ++n) {
    const ForwardSample s = forwardSample(d.data, rng);
    const model::VectorA Ax = A * s.x;
    // lo <= A x <= hi  <=>  -tau_max <= tau <= tau_max, with A x - lo = tau + tau_max and hi - A x = tau_max - tau.
    EXPECT_LT((Ax - lo - (s.tau + tau_max)).cwiseAbs().maxCoeff(), 1e-7);
    EXPECT_LT((hi - Ax - (tau_max - s.tau)).cwiseAbs().maxCoeff(), 1e-7);
  }
}

TEST(WbcEquations, BoundsAreTheAccelerationBoxAndTheSlackSwitch) {
  VariableBounds bounds;
  accelerationBounds(Eigen::Vector3d(5.0, 6.0, 7.0), 22.0, &bounds);
  for (int i = 0; i < kNqdd; ++i) {
    const double expected = i == 0 ? 5.0 : i == 1 ? 6.0 : i == 2 ? 7.0 : 22.0;
    EXPECT_EQ(bounds.lb[i], -expected);
    EXPECT_EQ(bounds.ub[i], expected);
  }
  slackBounds(true, &bounds);
  EXPECT_EQ(bounds.lb.tail<kNeps>().maxCoeff(), -kInf);
  EXPECT_EQ(bounds.ub.tail<kNeps>().minCoeff(), kInf);
  slackBounds(false, &bounds);
  EXPECT_EQ(bounds.lb.tail<kNeps>().cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(bounds.ub.tail<kNeps>().cwiseAbs().maxCoeff(), 0.0);
}

// ---------------------------------------------------------------------------------------------------------------
// (11)/(16e) with (13), (14): the MFT rows, and (20): the SA-WBC rows.

// The polytope's rows at a generalized configuration, A q_a - b, written out here.
PolytopeVector polytopeRows(const WbcPolytope& P, const model::VectorQ& q) {
  PolytopeVector v;
  for (int r = 0; r < kNeps; ++r) {
    double s = -P.b[r];
    for (int i = 0; i < model::kNa; ++i) s += P.A(r, i) * q[model::kActuatedIndex[i]];
    v[r] = s;
  }
  return v;
}

TEST(WbcEquations, MftRowsAreTheTaylorPredictionOfThePolytopeEntryByEntry) {
  const WbcPolytope P = test::testPolytope();
  std::mt19937 rng(61);
  std::normal_distribution<double> qn(0.0, 0.4), vn(0.0, 2.0), an(0.0, 30.0);
  for (double dt : {0.05, 0.02, 0.1}) {
    for (int n = 0; n < 20; ++n) {
      model::VectorQ q = movingState().q, qd;
      for (int i = 0; i < model::kNq; ++i) {
        q[i] += qn(rng);
        qd[i] = vn(rng);
      }
      ConstraintMatrix A;
      ConstraintVector lo, hi;
      mftPolytopeRows(P.A, P.b, q, qd, dt, &A, &lo, &hi);
      ASSERT_EQ(A.rows(), kNeps);
      // (13) C = dt^2/2 A S_a and the -I on eps, every entry.
      for (int r = 0; r < kNeps; ++r) {
        for (int c = 0; c < kNx; ++c) {
          double expected = 0.0;
          for (int i = 0; i < model::kNa; ++i)
            if (c == model::kActuatedIndex[i]) expected = dt * dt / 2.0 * P.A(r, i);
          if (c == kNqdd + kNfc + r) expected = -1.0;
          EXPECT_NEAR(A(r, c), expected, 1e-15) << r << " " << c;
        }
        EXPECT_EQ(lo(r), -kInf);
      }
      // (13) once more from finite differences of the polytope rows along q: C = dt^2/2 d(A q_a - b)/dq.
      for (int c = 0; c < model::kNq; ++c) {
        const double h = 1e-6;
        model::VectorQ qp = q, qm = q;
        qp[c] += h;
        qm[c] -= h;
        const PolytopeVector slope = (polytopeRows(P, qp) - polytopeRows(P, qm)) / (2 * h);
        EXPECT_LT((A.col(c).head<kNeps>() - dt * dt / 2.0 * slope).cwiseAbs().maxCoeff(), 1e-10) << c;
      }
      // (14) d = b - A (q_a + qd_a dt): minus the polytope rows at the linear part of the prediction.
      const PolytopeVector d_expected = -polytopeRows(P, q + dt * qd);
      EXPECT_LT((hi - d_expected).cwiseAbs().maxCoeff(), 1e-12);
      // Together: C qdd - d is the polytope rows at the full prediction q + qd dt + qdd dt^2 / 2 (eps = 0).
      for (int t = 0; t < 5; ++t) {
        Eigen::Matrix<double, kNx, 1> x = Eigen::Matrix<double, kNx, 1>::Zero();
        model::VectorQ qdd;
        for (int i = 0; i < model::kNq; ++i) qdd[i] = an(rng);
        x.head<kNqdd>() = qdd;
        const PolytopeVector lhs = A * x - hi;
        EXPECT_LT((lhs - polytopeRows(P, q + dt * qd + dt * dt / 2.0 * qdd)).cwiseAbs().maxCoeff(), 1e-12);
      }
    }
  }
}

// (11) = (16e): with eps = 0 the rows hold exactly when the predicted actuated pose is inside the polytope, and the
// smallest slack that makes them hold is the predicted pose's violation (10).
TEST(WbcEquations, InMftRowNeedsSlackExactlyWhereThePredictionLeavesThePolytope) {
  const WbcPolytope P = test::testPolytope();
  const model::RobotStateEstimate st = movingState();
  const double dt = 0.05;
  ConstraintMatrix A;
  ConstraintVector lo, hi;
  mftPolytopeRows(P.A, P.b, st.q, st.qd, dt, &A, &lo, &hi);
  std::mt19937 rng(67);
  std::normal_distribution<double> an(0.0, 150.0);
  int inside = 0, outside = 0;
  for (int n = 0; n < 2000; ++n) {
    Eigen::Matrix<double, kNx, 1> x = Eigen::Matrix<double, kNx, 1>::Zero();
    for (int i = 0; i < kNqdd; ++i) x[i] = an(rng);
    model::VectorA qa_pred;
    for (int i = 0; i < model::kNa; ++i) {
      const int j = model::kActuatedIndex[i];
      qa_pred[i] = st.q[j] + st.qd[j] * dt + x[j] * dt * dt / 2.0;
    }
    const double violation = model::polytopeViolation(P.A, P.b, qa_pred);
    const PolytopeVector excess = A * x - hi;  // eps = 0
    if (std::abs(violation) < 1e-9) continue;  // on the boundary: either answer is rounding
    EXPECT_EQ((excess.array() <= 0.0).all(), violation < 0.0);
    // Smallest eps per row: max(0, excess); its largest entry is the violation when outside.
    const PolytopeVector eps = excess.cwiseMax(0.0);
    x.tail<kNeps>() = eps;
    EXPECT_LE((A * x - hi).maxCoeff(), 1e-12);
    EXPECT_NEAR(eps.maxCoeff(), std::max(0.0, violation), 1e-12);
    (violation < 0.0 ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 100);
}

TEST(WbcEquations, PassiveRowsPredictTheKneesAndClipToTheReachOfTheBox) {
  const model::RobotStateEstimate st = movingState();
  const double dt = 0.05, qdd_max = 22.0;
  const double s = dt * dt / 2.0, reach = s * qdd_max;
  model::VectorA lo, hi;
  for (int i = 0; i < model::kNa; ++i) {
    const double knee = st.q[model::kPassiveIndex[i]] + st.qd[model::kPassiveIndex[i]] * dt;
    lo[i] = knee - 0.3;
    hi[i] = knee + 0.2;
  }
  ConstraintMatrix A;
  ConstraintVector lower, upper;
  passiveJointRows(st.q, st.qd, dt, lo, hi, qdd_max, &A, &lower, &upper);
  ASSERT_EQ(A.rows(), model::kNa);
  for (int r = 0; r < model::kNa; ++r)
    for (int c = 0; c < kNx; ++c) EXPECT_NEAR(A(r, c), c == model::kPassiveIndex[r] ? s : 0.0, 1e-18);
  // Reachable bounds (0.2 and 0.3 rad vs a reach of 0.0275 rad): the rows are lo - nominal, hi - nominal, clipped.
  for (int i = 0; i < model::kNa; ++i) {
    const int j = model::kPassiveIndex[i];
    const double nominal = st.q[j] + st.qd[j] * dt;
    EXPECT_NEAR(lower(i), std::min(lo[i] - nominal, reach), 1e-12);
    EXPECT_NEAR(upper(i), std::max(hi[i] - nominal, -reach), 1e-12);
  }
  // Bounds close enough to reach: a qdd satisfies the rows exactly when the predicted knee is inside.
  for (int i = 0; i < model::kNa; ++i) {
    const double knee = st.q[model::kPassiveIndex[i]] + st.qd[model::kPassiveIndex[i]] * dt;
    lo[i] = knee - 0.01;
    hi[i] = knee + 0.015;
  }
  passiveJointRows(st.q, st.qd, dt, lo, hi, qdd_max, &A, &lower, &upper);
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> a(-qdd_max, qdd_max);
  for (int n = 0; n < 500; ++n) {
    Eigen::Matrix<double, kNx, 1> x = Eigen::Matrix<double, kNx, 1>::Zero();
    for (int i = 0; i < kNqdd; ++i) x[i] = a(rng);
    const model::VectorA rows = A * x;
    for (int i = 0; i < model::kNa; ++i) {
      const int j = model::kPassiveIndex[i];
      const double knee = st.q[j] + st.qd[j] * dt + x[j] * dt * dt / 2.0;
      if (std::abs(knee - lo[i]) < 1e-12 || std::abs(knee - hi[i]) < 1e-12) continue;
      EXPECT_EQ(rows[i] >= lower(i) && rows[i] <= upper(i), knee >= lo[i] && knee <= hi[i]);
    }
  }
  // A bound out of reach (the estimate 0.1 rad past hi): the row asks for the strongest correction, qdd <= -qdd_max.
  for (int i = 0; i < model::kNa; ++i) {
    const double knee = st.q[model::kPassiveIndex[i]] + st.qd[model::kPassiveIndex[i]] * dt;
    hi[i] = knee - 0.1;
    lo[i] = knee - 0.5;
  }
  passiveJointRows(st.q, st.qd, dt, lo, hi, qdd_max, &A, &lower, &upper);
  for (int i = 0; i < model::kNa; ++i) {
    EXPECT_NEAR(upper(i), -reach, 1e-15);
    EXPECT_NEAR(upper(i) / s, -qdd_max, 1e-12);
    EXPECT_LE(lower(i), upper(i));  // still feasible
  }
}

}  // namespace
}  // namespace mft::wbc
