#include "model/mft_leg_inertia.hpp"

#include <cmath>

namespace mft::model {

namespace {
// d/da of a point at distance r along linkDirection(a).
Eigen::Vector2d tangent(double a, double r) { return r * Eigen::Vector2d(std::cos(a), std::sin(a)); }
}  // namespace

LegLinkJacobians legLinkJacobians(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p) {
  LegLinkJacobians J;
  // Knee rates are linear in the hip rates: probe with the unit vectors to get the 2x2 map.
  Eigen::Matrix2d knee;
  knee.col(0) = fiveBarKneeRates(g, p, Eigen::Vector2d(1.0, 0.0));
  knee.col(1) = fiveBarKneeRates(g, p, Eigen::Vector2d(0.0, 1.0));
  J.shank_rate = knee + Eigen::Matrix2d::Identity();  // alpha_i = q_i + knee_i
  const double q[2] = {p.q_rear, p.q_fore};
  const double alpha[2] = {p.shank_rear, p.shank_fore};
  for (int i = 0; i < 2; ++i) {
    J.thigh_com[i].setZero();
    J.thigh_com[i].col(i) = tangent(q[i], m.thigh.com_from_joint_m);
    // Shank CoM = knee + c2 * dir(alpha): knee moves with hip i only, the shank turns at alpha_i's rate.
    J.shank_com[i] = tangent(alpha[i], m.shank.com_from_joint_m) * J.shank_rate.row(i);
    J.shank_com[i].col(i) += tangent(q[i], g.l1);
  }
  J.foot = fiveBarFootJacobian(g, p);
  return J;
}

Eigen::Matrix2d legActuatedInertia(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p) {
  const LegLinkJacobians J = legLinkJacobians(g, m, p);
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 2; ++i) {
    M(i, i) += m.thigh.inertia_kgm2 + m.thigh.mass_kg * m.thigh.com_from_joint_m * m.thigh.com_from_joint_m;
    M += m.shank.mass_kg * J.shank_com[i].transpose() * J.shank_com[i];
    const Eigen::RowVector2d w = J.shank_rate.row(i);
    M += m.shank.inertia_kgm2 * w.transpose() * w;
  }
  M += m.foot_mass_kg * J.foot.transpose() * J.foot;
  return 0.5 * (M + M.transpose());
}

Eigen::Vector2d legGravityTorque(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p,
                                 double gravity_mps2) {
  const LegLinkJacobians J = legLinkJacobians(g, m, p);
  Eigen::Vector2d G = m.foot_mass_kg * J.foot.row(1).transpose();
  for (int i = 0; i < 2; ++i)
    G += m.thigh.mass_kg * J.thigh_com[i].row(1).transpose() + m.shank.mass_kg * J.shank_com[i].row(1).transpose();
  return gravity_mps2 * G;
}

}  // namespace mft::model
