#pragma once
// Closed-chain inertia of one five-bar leg in actuated coordinates, base fixed (docs/reference/five-bar-theory.md#acceleration-capacity-raci-and-leg-inertia):
// M_a = sum over links of (m Jv' Jv + I Jw' Jw), every link velocity written as a function of the two hip
// rates through the loop closure (five-bar knee rates). Rotor inertia is not included: RACI adds it through
// the drive constant k. Independent of the full-body dynamics on purpose (a second, simpler derivation).
#include <Eigen/Core>

#include "model/five_bar.hpp"
#include "model/robot_description.hpp"

namespace mft::model {

struct LegInertiaParams {
  LinkParams thigh;
  LinkParams shank;
  double foot_mass_kg = 0.0;  // optional point mass at the foot (tests, payload studies)
  static LegInertiaParams from(const RobotDescription& d) { return {d.thigh, d.shank, 0.0}; }
};

// Jacobians of one leg at a pose w.r.t. (q_rear, q_fore). Rows 0-1 of a CoM Jacobian are (x, z).
struct LegLinkJacobians {
  Eigen::Matrix2d thigh_com[2];    // rear, fore
  Eigen::Matrix2d shank_com[2];
  Eigen::Matrix2d shank_rate;      // rows: absolute shank angle rates (rear, fore)
  Eigen::Matrix2d foot;            // d foot / d q_a
};

// Needs a pose away from the output singularity (the knee rates go through J^-1 of the foot).
LegLinkJacobians legLinkJacobians(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p);

// M_a (2x2, symmetric, positive semi-definite).
Eigen::Matrix2d legActuatedInertia(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p);

// Hip torques that hold the leg against gravity (base fixed, z up): G = sum m g Jv_z'.
Eigen::Vector2d legGravityTorque(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p,
                                 double gravity_mps2);

}  // namespace mft::model
