#pragma once
// Per-tick dynamics terms of Problem 1 that several rows share: the floating-base rows of the closure-
// projected dynamics (paper eq. 3 / 16a) and the affine map of the actuated torques (paper eq. 7):
//   tau_a = tau_qdd qdd + tau_fc f_c + tau_0,
//   tau_qdd = K S_a M,  tau_fc = -K S_a N_h' J_c',  tau_0 = K S_a (N_h' h + J_h' Lambda_h Jdot_h qd),
//   K = (S_a N_h' S_a')^-1.
#include <Eigen/Core>

#include "model/coordinates.hpp"
#include "model/planar_dynamics.hpp"

namespace mft::wbc {

struct DynamicsTerms {
  Eigen::Matrix<double, 3, model::kNq> base_NhT;  // S_f N_h' (3 x 11)
  Eigen::Matrix<double, model::kNa, model::kNq> tau_qdd;
  Eigen::Matrix<double, model::kNa, model::kNc> tau_fc;
  model::VectorA tau_0;
};

// Needs data filled by updateModel and proj by closureProjection for the same state. Allocation-free.
// Returns false if the result is not finite (e.g. S_a N_h' S_a' singular at a leg singularity).
bool computeDynamicsTerms(const model::ModelData& data, const model::ClosureProjection& proj, DynamicsTerms* out);

}  // namespace mft::wbc
