#pragma once
// Generalized coordinates of the paper: q = [x, z, pitch, q4..q11] (11). Planar angles are CCW seen with x to
// the right and z up (about -y): pitch > 0 = nose up. Leg 0 is the right leg (q4..q7), leg 1 the left (q8..q11).
// Per leg: hip_rear (actuated), knee_rear (passive), hip_fore (actuated), knee_fore (passive).
// Contact forces f_c = [f_x, f_z] of the right foot, then of the left foot (ground on foot, world frame).
#include <Eigen/Core>
#include <array>

namespace mft::model {

constexpr int kNq = 11;        // generalized coordinates
constexpr int kNa = 4;         // actuated joints
constexpr int kNc = 4;         // contact force components (2 feet x [x, z])
constexpr int kNh = 4;         // loop-closure rows (2 legs x [x, z])
constexpr int kNumLegs = 2;

enum : int { kBaseX = 0, kBaseZ = 1, kBasePitch = 2 };
enum Leg : int { kRightLeg = 0, kLeftLeg = 1 };

constexpr int hipRearIndex(int leg) { return 3 + 4 * leg; }
constexpr int kneeRearIndex(int leg) { return 4 + 4 * leg; }
constexpr int hipForeIndex(int leg) { return 5 + 4 * leg; }
constexpr int kneeForeIndex(int leg) { return 6 + 4 * leg; }

// Actuated joints in the order of tau_a: [q4, q6, q8, q10] = right rear, right fore, left rear, left fore.
constexpr std::array<int, kNa> kActuatedIndex = {3, 5, 7, 9};
// Passive (underactuated) joints [q5, q7, q9, q11].
constexpr std::array<int, kNa> kPassiveIndex = {4, 6, 8, 10};

using VectorQ = Eigen::Matrix<double, kNq, 1>;
using MatrixQ = Eigen::Matrix<double, kNq, kNq>;
using VectorA = Eigen::Matrix<double, kNa, 1>;
using VectorC = Eigen::Matrix<double, kNc, 1>;
using VectorH = Eigen::Matrix<double, kNh, 1>;
using MatrixCQ = Eigen::Matrix<double, kNc, kNq>;
using MatrixHQ = Eigen::Matrix<double, kNh, kNq>;
using MatrixAQ = Eigen::Matrix<double, kNa, kNq>;

// S_a (4 x 11): selects the actuated joints.
inline MatrixAQ actuationSelector() {
  MatrixAQ S = MatrixAQ::Zero();
  for (int i = 0; i < kNa; ++i) S(i, kActuatedIndex[i]) = 1.0;
  return S;
}
// S_ua (4 x 11): selects the passive joints.
inline MatrixAQ passiveSelector() {
  MatrixAQ S = MatrixAQ::Zero();
  for (int i = 0; i < kNa; ++i) S(i, kPassiveIndex[i]) = 1.0;
  return S;
}

}  // namespace mft::model
