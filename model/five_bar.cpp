#include "model/five_bar.hpp"

#include <algorithm>
#include <cmath>

namespace mft::model {

double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * M_PI);  // [-pi, pi]
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

namespace {
// Absolute angle (CCW from the downward axis) of a vector.
double angleFromDown(const Eigen::Vector2d& v) { return std::atan2(v.x(), -v.y()); }

void fillShanks(const FiveBarGeometry& g, FiveBarPose* p) {
  p->shank_rear = angleFromDown(p->foot - p->knee_point_rear);
  p->shank_fore = angleFromDown(p->foot - p->knee_point_fore);
  p->knee_rear = wrapAngle(p->shank_rear - p->q_rear);
  p->knee_fore = wrapAngle(p->shank_fore - p->q_fore);
  (void)g;
}
}  // namespace

FiveBarStatus fiveBarForward(const FiveBarGeometry& g, double q_rear, double q_fore, FiveBarPose* out) {
  FiveBarPose& p = *out;
  p.q_rear = q_rear;
  p.q_fore = q_fore;
  p.knee_point_rear = g.hipRear() + g.l1 * linkDirection(q_rear);
  p.knee_point_fore = g.hipFore() + g.l1 * linkDirection(q_fore);
  const Eigen::Vector2d span = p.knee_point_fore - p.knee_point_rear;
  const double dist = span.norm();
  if (dist < 1e-12) return FiveBarStatus::Degenerate;
  if (dist > 2.0 * g.l2) return FiveBarStatus::Unreachable;
  const Eigen::Vector2d w = span / dist;
  const Eigen::Vector2d normal(w.y(), -w.x());  // (B_f - B_r) x normal < 0: the foot below the knee line
  const double height = std::sqrt(std::max(0.0, g.l2 * g.l2 - 0.25 * dist * dist));
  p.foot = 0.5 * (p.knee_point_rear + p.knee_point_fore) + height * normal;
  fillShanks(g, &p);
  return FiveBarStatus::Ok;
}

FiveBarStatus fiveBarInverse(const FiveBarGeometry& g, const Eigen::Vector2d& foot, FiveBarPose* out) {
  FiveBarPose& p = *out;
  double q[2];
  const Eigen::Vector2d hips[2] = {g.hipRear(), g.hipFore()};
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d v = foot - hips[i];
    const double dist = v.norm();
    if (dist > g.l1 + g.l2 || dist < std::abs(g.l2 - g.l1) || dist < 1e-12) return FiveBarStatus::Unreachable;
    const double c = (g.l1 * g.l1 + dist * dist - g.l2 * g.l2) / (2.0 * g.l1 * dist);
    const double opening = std::acos(std::clamp(c, -1.0, 1.0));
    // The rear thigh turns back (clockwise) from the hip-foot line, the fore thigh forward.
    q[i] = angleFromDown(v) + (i == 0 ? -opening : opening);
  }
  p.q_rear = q[0];
  p.q_fore = q[1];
  p.knee_point_rear = hips[0] + g.l1 * linkDirection(q[0]);
  p.knee_point_fore = hips[1] + g.l1 * linkDirection(q[1]);
  p.foot = foot;
  fillShanks(g, &p);
  return FiveBarStatus::Ok;
}

Eigen::Matrix2d fiveBarFootJacobian(const FiveBarGeometry& g, const FiveBarPose& p) {
  // Each shank is rigid: u_i . Cdot = u_i . Bdot_i = l1 qdot_i (t_i . u_i), t_i = d/dq (sin q, -cos q).
  // Stack both rows: [u_r'; u_f'] Cdot = diag(l1 t_r.u_r, l1 t_f.u_f) qdot  =>  J = U^-1 D.
  const Eigen::Vector2d u_r = linkDirection(p.shank_rear), u_f = linkDirection(p.shank_fore);
  const Eigen::Vector2d t_r(std::cos(p.q_rear), std::sin(p.q_rear)), t_f(std::cos(p.q_fore), std::sin(p.q_fore));
  Eigen::Matrix2d U;
  U.row(0) = u_r.transpose();
  U.row(1) = u_f.transpose();
  const Eigen::Matrix2d D = Eigen::Vector2d(g.l1 * t_r.dot(u_r), g.l1 * t_f.dot(u_f)).asDiagonal();
  return U.inverse() * D;
}

Eigen::Vector2d fiveBarKneeRates(const FiveBarGeometry& g, const FiveBarPose& p, const Eigen::Vector2d& hip_rates) {
  const Eigen::Vector2d foot_vel = fiveBarFootJacobian(g, p) * hip_rates;
  const double q[2] = {p.q_rear, p.q_fore};
  const double alpha[2] = {p.shank_rear, p.shank_fore};
  Eigen::Vector2d knee_rates;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d knee_vel = g.l1 * hip_rates[i] * Eigen::Vector2d(std::cos(q[i]), std::sin(q[i]));
    const Eigen::Vector2d t_alpha(std::cos(alpha[i]), std::sin(alpha[i]));
    const double alpha_rate = t_alpha.dot(foot_vel - knee_vel) / g.l2;
    knee_rates[i] = alpha_rate - hip_rates[i];
  }
  return knee_rates;
}

}  // namespace mft::model
