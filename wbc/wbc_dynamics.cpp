#include "wbc/wbc_dynamics.hpp"

namespace mft::wbc {

bool computeDynamicsTerms(const model::ModelData& data, const model::ClosureProjection& proj, DynamicsTerms* out) {
  // The floating-base rows of (7); (8) needs only S_f N_h' of them (S_f M and S_f H are read from data).
  model::ProjectedDynamicsRows<3> base;
  model::projectedDynamicsRows<3>(data, proj, model::kBaseIndex, &base);
  out->base_NhT = base.NhT;
  return model::actuatedTorqueMap(data, proj, &out->torque) && out->base_NhT.allFinite();
}

}  // namespace mft::wbc
