#include "wbc/qp/qp_kkt.hpp"

#include <algorithm>
#include <cmath>

namespace mft::qp {
namespace {

// Residuals of one two-sided constraint lo <= v <= hi with multiplier y; updates r.
void sideResiduals(double v, double lo, double hi, double y, KktResiduals& r) {
  r.primal = std::max({r.primal, lo - v, v - hi});
  if (lo == hi) return;  // fixed: any sign, always tight
  if (y > 0.0) {
    r.dual = std::max(r.dual, lo == -kInf ? y : 0.0);
    if (lo > -kInf) r.complementarity = std::max(r.complementarity, y * std::abs(v - lo));
  } else if (y < 0.0) {
    r.dual = std::max(r.dual, hi == kInf ? -y : 0.0);
    if (hi < kInf) r.complementarity = std::max(r.complementarity, -y * std::abs(hi - v));
  }
}

}  // namespace

double KktResiduals::max() const { return std::max({stationarity, primal, dual, complementarity}); }

KktResiduals kktResiduals(const QpProblem& p, const QpSolution& s) {
  KktResiduals r;
  if (s.x.size() != p.n || s.y_eq.size() != p.neq || s.y_bounds.size() != p.n || s.y_rows.size() != p.nin) {
    r.stationarity = r.primal = r.dual = r.complementarity = kInf;
    return r;
  }
  const Eigen::VectorXd grad = p.H * s.x + p.g - p.Aeq.transpose() * s.y_eq - s.y_bounds - p.Ain.transpose() * s.y_rows;
  r.stationarity = grad.size() ? grad.cwiseAbs().maxCoeff() : 0.0;
  if (p.neq) r.primal = (p.Aeq * s.x - p.beq).cwiseAbs().maxCoeff();
  for (int j = 0; j < p.n; ++j) sideResiduals(s.x[j], p.lb[j], p.ub[j], s.y_bounds[j], r);
  const Eigen::VectorXd rows = p.Ain * s.x;
  for (int i = 0; i < p.nin; ++i) sideResiduals(rows[i], p.lbA[i], p.ubA[i], s.y_rows[i], r);
  // NaN anywhere must not look like success.
  if (std::isnan(r.stationarity) || std::isnan(r.primal) || !s.x.allFinite()) r.stationarity = kInf;
  return r;
}

}  // namespace mft::qp
