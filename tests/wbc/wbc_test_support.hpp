#pragma once
// Shared fixtures of the WBC tests: the project's robot and config, closed-loop states with consistent
// velocities, a reference that holds the current pose, and an MFT hexagon per leg built here from the robot
// geometry (so the tests do not depend on the offline tool's output).
#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <string>

#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/wbc_formulation.hpp"
#include "wbc/wbc_reference.hpp"

namespace mft::wbc::test {

inline const model::RobotDescription& robot() {
  static const model::RobotDescription r = model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  return r;
}

inline WbcConfig projectConfig(WbcVariant v) {
  WbcConfig c = loadWbcConfig(std::string(MFT_CONFIG_DIR) + "/wbc.yaml");
  c.variant = v;
  return c;
}

// Vertical hip-foot distance of a symmetric stance with thigh half-opening theta (coaxial hips).
inline double stanceDistance(double theta) {
  const double l1 = robot().thigh.length_m, l2 = robot().shank.length_m;
  const double s = l1 * std::sin(theta);
  return l1 * std::cos(theta) + std::sqrt(l2 * l2 - s * s);
}
// Thigh opening q_fore - q_rear that puts the foot at distance d (d decreases with the opening).
inline double openingForDistance(double d) {
  double lo = 0.0, hi = 1.5;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (stanceDistance(mid) > d ? lo : hi) = mid;
  }
  return lo + hi;  // 2 theta
}

// Hexagon per leg in (q_rear, q_fore): the MFT band d in [d_lo, d_hi] (docs/reference/five-bar-theory.md#vertical-stance-numbers: [0.199, 0.435] m)
// as two edges on the opening, cut by the hip-limit box. Unit-normal rows, 6 per leg.
inline WbcPolytope testPolytope(double d_lo = 0.199, double d_hi = 0.435) {
  WbcPolytope p;
  const double open_max = openingForDistance(d_lo), open_min = openingForDistance(d_hi);
  const double r = 1.0 / std::sqrt(2.0);
  const auto& rb = robot();
  for (int leg = 0; leg < 2; ++leg) {
    const int c_r = 2 * leg, c_f = 2 * leg + 1, row = 6 * leg;
    p.A(row + 0, c_f) = r;  p.A(row + 0, c_r) = -r; p.b(row + 0) = r * open_max;
    p.A(row + 1, c_f) = -r; p.A(row + 1, c_r) = r;  p.b(row + 1) = -r * open_min;
    p.A(row + 2, c_r) = 1;  p.b(row + 2) = rb.rear_hip_rad.hi;
    p.A(row + 3, c_r) = -1; p.b(row + 3) = -rb.rear_hip_rad.lo;
    p.A(row + 4, c_f) = 1;  p.b(row + 4) = rb.fore_hip_rad.hi;
    p.A(row + 5, c_f) = -1; p.b(row + 5) = -rb.fore_hip_rad.lo;
  }
  return p;
}

struct StateSpec {
  Eigen::Vector3d base{0.0, 0.40, 0.0};      // x, z, pitch
  Eigen::Vector3d base_vel{0.0, 0.0, 0.0};
  Eigen::Vector2d right_foot{0.05, -0.40};   // in the base frame
  Eigen::Vector2d left_foot{-0.05, -0.40};
  Eigen::Vector2d right_foot_vel{0.0, 0.0};  // relative to the base frame
  Eigen::Vector2d left_foot_vel{0.0, 0.0};
};

// A closed-loop state whose velocity satisfies J_h qd = 0 (central differences of the exact configuration).
inline model::RobotStateEstimate makeState(const StateSpec& s, std::uint64_t tick = 0) {
  model::RobotStateEstimate st;
  st.tick = tick;
  st.q = model::closedLoopConfiguration(robot(), s.base, s.right_foot, s.left_foot);
  const double h = 1e-6;
  const model::VectorQ qp = model::closedLoopConfiguration(robot(), s.base + h * s.base_vel, s.right_foot + h * s.right_foot_vel,
                                                           s.left_foot + h * s.left_foot_vel);
  const model::VectorQ qm = model::closedLoopConfiguration(robot(), s.base - h * s.base_vel, s.right_foot - h * s.right_foot_vel,
                                                           s.left_foot - h * s.left_foot_vel);
  st.qd = (qp - qm) / (2 * h);
  st.contact = {true, true};
  return st;
}

// A reference that holds the current base height/pitch and foot positions (world), zero velocity/acceleration.
inline WbcReference holdReference(const model::RobotStateEstimate& st, bool right_stance = true, bool left_stance = true) {
  model::PlanarModel m = model::buildBipedModel(robot());
  model::ModelData d;
  model::updateModel(m, st.q, st.qd, &d);
  WbcReference r;
  r.tick = st.tick;
  r.foot_in_stance = {right_stance, left_stance};
  r.base_z.pos = st.q[model::kBaseZ];
  r.base_pitch.pos = st.q[model::kBasePitch];
  r.foot_pos = d.foot_pos;
  return r;
}

}  // namespace mft::wbc::test
