#include "wbc/qp/qp_problem.hpp"

namespace mft::qp {

void QpProblem::resize(int n_, int neq_, int nin_) {
  n = n_;
  neq = neq_;
  nin = nin_;
  H.setZero(n, n);
  g.setZero(n);
  Aeq.setZero(neq, n);
  beq.setZero(neq);
  Ain.setZero(nin, n);
  lbA.setConstant(nin, -kInf);
  ubA.setConstant(nin, kInf);
  lb.setConstant(n, -kInf);
  ub.setConstant(n, kInf);
  dense_block = 0;
}

void QpSolution::resize(int n, int neq, int nin) {
  x.resize(n);
  active.resize(n + nin);
  y_eq.resize(neq);
  y_bounds.resize(n);
  y_rows.resize(nin);
}

const char* toString(QpStatus s) {
  switch (s) {
    case QpStatus::Optimal: return "optimal";
    case QpStatus::Infeasible: return "infeasible";
    case QpStatus::IterationLimit: return "iteration_limit";
    case QpStatus::NumericalFailure: return "numerical_failure";
  }
  return "unknown";
}

int detectDenseBlock(const Eigen::MatrixXd& H) {
  const int n = static_cast<int>(H.rows());
  // The block ends after the last row/column that has an off-diagonal entry to an earlier index.
  int k = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < j; ++i)
      if (H(i, j) != 0.0 || H(j, i) != 0.0) k = j + 1;
  // A diagonal H is a 1x1 "dense" block plus a diagonal rest (0 would mean "dense").
  return (n > 0 && k == 0) ? 1 : k;
}

}  // namespace mft::qp
