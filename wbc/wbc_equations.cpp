#include "wbc/wbc_equations.hpp"

#include <algorithm>
#include <limits>

namespace mft::wbc {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
using model::kNa;
}  // namespace

double pdAcceleration(const Setpoint1& ref, double pos, double vel, const PdGains1& g) {
  return ref.acc + g.kp * (ref.pos - pos) + g.kd * (ref.vel - vel);
}

void coordinateTaskRows(int index, double xdd_des, TaskMatrix* A, TaskVector* b) {
  A->setZero(1, kNqdd);
  (*A)(0, index) = 1.0;
  b->resize(1);
  (*b)(0) = xdd_des;
}

void footTaskRows(const model::MatrixCQ& Jc, const model::VectorC& Jc_dot_qd, int leg, const Eigen::Vector2d& xdd_des,
                  TaskMatrix* A, TaskVector* b) {
  const int r = 2 * leg;
  *A = Jc.middleRows<2>(r);
  b->resize(2);
  for (int i = 0; i < 2; ++i) (*b)(i) = xdd_des[i] - Jc_dot_qd[r + i];
}

void contactForceTaskRows(TaskMatrix* A, TaskVector* b) {
  A->setIdentity(kNfc, kNfc);
  b->setZero(kNfc);
}

void contactForceRateTaskRows(const model::VectorC& fc_prev, TaskMatrix* A, TaskVector* b) {
  A->setIdentity(kNfc, kNfc);
  *b = fc_prev;
}

model::VectorC initialPreviousContactForce(double weight_N, const std::array<bool, model::kNumLegs>& stance) {
  model::VectorC fc = model::VectorC::Zero();
  const int n_stance = static_cast<int>(stance[0]) + static_cast<int>(stance[1]);
  for (int leg = 0; leg < model::kNumLegs; ++leg)
    if (stance[leg]) fc[2 * leg + 1] = weight_N / n_stance;
  return fc;
}

void slackTaskRows(TaskMatrix* A, TaskVector* b) {
  A->setIdentity(kNeps, kNeps);
  b->setZero(kNeps);
}

void baseDynamicsRows(const model::MatrixQ& M, const model::VectorQ& H, const model::MatrixCQ& Jc,
                      const Eigen::Matrix<double, 3, model::kNq>& base_NhT, ConstraintMatrix* A, ConstraintVector* rhs) {
  A->setZero(3, kNx);
  A->block<3, kNqdd>(0, 0) = M.topRows<3>();
  A->block<3, kNfc>(0, kNqdd).noalias() = -base_NhT * Jc.transpose();
  rhs->resize(3);
  rhs->noalias() = -base_NhT * H;
}

void loopClosureRows(const model::MatrixHQ& Jh, const model::VectorH& Jh_dot_qd, ConstraintMatrix* A,
                     ConstraintVector* rhs) {
  A->setZero(model::kNh, kNx);
  A->block<model::kNh, kNqdd>(0, 0) = Jh;
  *rhs = -Jh_dot_qd;
}

void frictionPyramidRows(double mu, ConstraintMatrix* A, ConstraintVector* lower, ConstraintVector* upper) {
  A->setZero(4, kNx);
  lower->resize(4);
  upper->resize(4);
  for (int foot = 0; foot < 2; ++foot) {
    for (int s = 0; s < 2; ++s) {
      const int r = 2 * foot + s;
      (*A)(r, kNqdd + 2 * foot) = s == 0 ? 1.0 : -1.0;
      (*A)(r, kNqdd + 2 * foot + 1) = -mu;
      (*lower)(r) = -kInf;
      (*upper)(r) = 0.0;
    }
  }
}

void torqueLimitRows(const model::ActuatedTorqueMap& torque, const model::VectorA& tau_max, ConstraintMatrix* A,
                     ConstraintVector* lower, ConstraintVector* upper) {
  A->setZero(kNa, kNx);
  A->block<kNa, kNqdd>(0, 0) = torque.tau_qdd;
  A->block<kNa, kNfc>(0, kNqdd) = torque.tau_fc;
  *lower = -tau_max - torque.tau_0;
  *upper = tau_max - torque.tau_0;
}

void mftPolytopeRows(const PolytopeMatrix& A_poly, const PolytopeVector& b_poly, const model::VectorQ& q,
                     const model::VectorQ& qd, double dt, ConstraintMatrix* A, ConstraintVector* lower,
                     ConstraintVector* upper) {
  A->setZero(kNeps, kNx);
  model::VectorA qa_pred;
  for (int i = 0; i < kNa; ++i) {
    const int j = model::kActuatedIndex[i];
    qa_pred[i] = predictedCoordinate(q[j], qd[j], 0.0, dt);
    A->col(j) = 0.5 * dt * dt * A_poly.col(i);
  }
  A->block<kNeps, kNeps>(0, kNqdd + kNfc) = -Eigen::Matrix<double, kNeps, kNeps>::Identity();
  lower->setConstant(kNeps, -kInf);
  upper->resize(kNeps);
  upper->noalias() = b_poly - A_poly * qa_pred;
}

void passiveJointRows(const model::VectorQ& q, const model::VectorQ& qd, double dt, const model::VectorA& passive_lo,
                      const model::VectorA& passive_hi, double qdd_joint_max, ConstraintMatrix* A,
                      ConstraintVector* lower, ConstraintVector* upper) {
  A->setZero(kNa, kNx);
  lower->resize(kNa);
  upper->resize(kNa);
  const double s = 0.5 * dt * dt;
  const double reach = s * qdd_joint_max;
  for (int i = 0; i < kNa; ++i) {
    const int j = model::kPassiveIndex[i];
    const double nominal = predictedCoordinate(q[j], qd[j], 0.0, dt);
    (*A)(i, j) = s;
    (*lower)(i) = std::min(passive_lo[i] - nominal, reach);
    (*upper)(i) = std::max(passive_hi[i] - nominal, -reach);
  }
}

void accelerationBounds(const Eigen::Vector3d& qdd_base_max, double qdd_joint_max, VariableBounds* bounds) {
  for (int i = 0; i < kNqdd; ++i) {
    const double m = i < 3 ? qdd_base_max[i] : qdd_joint_max;
    bounds->lb[i] = -m;
    bounds->ub[i] = m;
  }
}

void contactForceBounds(const std::array<bool, model::kNumLegs>& stance, double fz_max, VariableBounds* bounds) {
  for (int foot = 0; foot < 2; ++foot) {
    const int ix = kNqdd + 2 * foot;
    bounds->lb[ix] = -kInf;
    bounds->ub[ix] = kInf;
    bounds->lb[ix + 1] = 0.0;
    bounds->ub[ix + 1] = stance[foot] ? fz_max : 0.0;
  }
}

void slackBounds(bool soft_mft, VariableBounds* bounds) {
  bounds->lb.tail<kNeps>().setConstant(soft_mft ? -kInf : 0.0);
  bounds->ub.tail<kNeps>().setConstant(soft_mft ? kInf : 0.0);
}

}  // namespace mft::wbc
