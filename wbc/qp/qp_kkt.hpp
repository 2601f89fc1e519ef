#pragma once
// KKT residuals of a QpSolution (multiplier convention of qp_problem.hpp:  H x + g = Aeq' y_eq + y_bounds + Ain' y_rows,
// y > 0 at the lower side, y < 0 at the upper side). Absolute values, infinity norms.
#include "wbc/qp/qp_problem.hpp"

namespace mft::qp {

struct KktResiduals {
  double stationarity = 0.0;     // |H x + g - Aeq' y_eq - y_bounds - Ain' y_rows|
  double primal = 0.0;           // equality residual and bound/row violation
  double dual = 0.0;             // wrong-sign multiplier (y > 0 needs a finite lower side, y < 0 a finite upper)
  double complementarity = 0.0;  // |y| times the slack of the side it belongs to
  double max() const;
};

// Sizes must match the problem (x, y_eq, y_bounds, y_rows); otherwise every residual is +infinity.
KktResiduals kktResiduals(const QpProblem& problem, const QpSolution& solution);

}  // namespace mft::qp
