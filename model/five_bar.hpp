#pragma once
// Kinematics of one planar five-bar leg (docs/reference/five-bar-theory.md#leg-geometry-and-conventions), in the leg frame = base frame:
// x forward, z up, hips at (-s/2, 0) (rear) and (+s/2, 0) (fore). Angles are CCW (about -y).
// Hip angle q_i is measured from the downward axis: knee B_i = A_i + l1 (sin q_i, -cos q_i).
// Shank angle alpha_i likewise: foot C = B_i + l2 (sin alpha_i, -cos alpha_i). Knee = alpha_i - q_i.
// Assembly mode: rear knee bends backward, fore knee forward, foot below the knee line.
#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>

#include "model/robot_description.hpp"

namespace mft::model {

struct FiveBarGeometry {
  double hip_spacing = 0.0;  // s
  double l1 = 0.0;           // thigh
  double l2 = 0.0;           // shank
  static FiveBarGeometry from(const RobotDescription& d) { return {d.hip_spacing_m, d.thigh.length_m, d.shank.length_m}; }
  Eigen::Vector2d hipRear() const { return {-0.5 * hip_spacing, 0.0}; }
  Eigen::Vector2d hipFore() const { return {0.5 * hip_spacing, 0.0}; }
};

enum class FiveBarStatus {
  Ok,
  Unreachable,  // the two knees are further apart than two shanks: the loop cannot close
  Degenerate,   // the knees coincide (coaxial hips, equal thigh angles): the foot is undetermined
};

struct FiveBarPose {
  double q_rear = 0.0, q_fore = 0.0;          // actuated hip angles
  double knee_rear = 0.0, knee_fore = 0.0;    // passive knee angles (relative)
  double shank_rear = 0.0, shank_fore = 0.0;  // absolute shank angles alpha_i
  Eigen::Vector2d knee_point_rear{0, 0}, knee_point_fore{0, 0}, foot{0, 0};
};

// Unit direction of a link at CCW angle a from the downward axis: (sin a, -cos a).
inline Eigen::Vector2d linkDirection(double a) { return {std::sin(a), -std::cos(a)}; }
// 2-D cross product a x b = a_x b_z - a_z b_x.
inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
// Wraps an angle to (-pi, pi].
double wrapAngle(double a);

// Forward kinematics from the two hip angles.
FiveBarStatus fiveBarForward(const FiveBarGeometry& g, double q_rear, double q_fore, FiveBarPose* out);

// Inverse kinematics from the foot point; fills the whole pose. Unreachable when the foot is farther than
// l1 + l2 or closer than |l2 - l1| to either hip.
FiveBarStatus fiveBarInverse(const FiveBarGeometry& g, const Eigen::Vector2d& foot, FiveBarPose* out);

// d foot / d (q_rear, q_fore) at a pose (2x2). Singular when the output transmission vanishes.
Eigen::Matrix2d fiveBarFootJacobian(const FiveBarGeometry& g, const FiveBarPose& p);

// Passive knee rates (rear, fore) from the hip rates at a pose, through the loop closure.
Eigen::Vector2d fiveBarKneeRates(const FiveBarGeometry& g, const FiveBarPose& p, const Eigen::Vector2d& hip_rates);

// The four leg coordinates in generalized-coordinate order [hip_rear, knee_rear, hip_fore, knee_fore].
inline std::array<double, 4> legCoordinates(const FiveBarPose& p) { return {p.q_rear, p.knee_rear, p.q_fore, p.knee_fore}; }

}  // namespace mft::model
