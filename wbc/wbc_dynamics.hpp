#pragma once
// Per-tick dynamics terms of Problem 1 that several rows share: the floating-base rows of the closure-
// projected dynamics (paper (8) = (16a)) and the actuated torque as an affine map of (qdd, f_c) (paper (9),
// model::actuatedTorqueMap). The QP's torque rows and the decoded command both read `torque`.
#include <Eigen/Core>

#include "model/coordinates.hpp"
#include "model/planar_dynamics.hpp"

namespace mft::wbc {

struct DynamicsTerms {
  Eigen::Matrix<double, 3, model::kNq> base_NhT;  // S_f N_h' (3 x 11)
  model::ActuatedTorqueMap torque;
};

// Needs data filled by updateModel and proj by closureProjection for the same state. Allocation-free.
// Returns false if the result is not finite (e.g. S_a N_h' S_a' singular at a leg singularity).
bool computeDynamicsTerms(const model::ModelData& data, const model::ClosureProjection& proj, DynamicsTerms* out);

}  // namespace mft::wbc
