#include "wbc/wbc_dynamics.hpp"

namespace mft::wbc {

bool computeDynamicsTerms(const model::ModelData& data, const model::ClosureProjection& proj, DynamicsTerms* out) {
  // Rows of N_h' are columns of N_h: S_f N_h' = first three columns of N_h, transposed.
  out->base_NhT = proj.N_h.leftCols<3>().transpose();
  return model::actuatedTorqueMap(data, proj, &out->torque) && out->base_NhT.allFinite();
}

}  // namespace mft::wbc
