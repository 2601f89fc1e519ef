#include "wbc/wbc_dynamics.hpp"

#include <Eigen/LU>

namespace mft::wbc {

using model::kActuatedIndex;
using model::kNa;
using model::kNq;

bool computeDynamicsTerms(const model::ModelData& data, const model::ClosureProjection& proj, DynamicsTerms* out) {
  // Rows of N_h' are columns of N_h: S_f N_h' = first three columns of N_h, transposed.
  out->base_NhT = proj.N_h.leftCols<3>().transpose();

  Eigen::Matrix<double, kNa, kNq> SaNhT;  // S_a N_h'
  Eigen::Matrix<double, kNa, kNq> SaM;    // S_a M
  Eigen::Matrix<double, kNa, model::kNh> SaJhT;  // S_a J_h'
  Eigen::Matrix<double, kNa, kNa> SaNhTSaT;
  for (int i = 0; i < kNa; ++i) {
    const int j = kActuatedIndex[i];
    SaNhT.row(i) = proj.N_h.col(j).transpose();
    SaM.row(i) = data.M.row(j);
    SaJhT.row(i) = data.Jh.col(j).transpose();
  }
  for (int k = 0; k < kNa; ++k) SaNhTSaT.col(k) = SaNhT.col(kActuatedIndex[k]);

  // 4x4 with a closed-form inverse in Eigen: no pivoting search, no allocation.
  const Eigen::Matrix<double, kNa, kNa> K = SaNhTSaT.inverse();
  out->tau_qdd.noalias() = K * SaM;
  const Eigen::Matrix<double, kNa, model::kNc> SaNhTJcT = SaNhT * data.Jc.transpose();
  out->tau_fc.noalias() = -K * SaNhTJcT;
  const model::VectorH lambda_jdqd = proj.Lambda_h * data.Jh_dot_qd;
  const model::VectorA inner = SaNhT * data.h + SaJhT * lambda_jdqd;
  out->tau_0.noalias() = K * inner;
  return out->base_NhT.allFinite() && out->tau_qdd.allFinite() && out->tau_fc.allFinite() && out->tau_0.allFinite();
}

}  // namespace mft::wbc
