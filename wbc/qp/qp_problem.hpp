#pragma once
// A dense convex QP:  min 1/2 x'Hx + g'x  s.t.  Aeq x = beq,  lbA <= Ain x <= ubA,  lb <= x <= ub.
// +-infinity marks a missing side; lb == ub fixes a variable. Storage is sized once by resize().
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace mft::qp {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct QpProblem {
  int n = 0, neq = 0, nin = 0;
  Eigen::MatrixXd H;      // n x n, symmetric positive definite
  Eigen::VectorXd g;      // n
  Eigen::MatrixXd Aeq;    // neq x n
  Eigen::VectorXd beq;    // neq
  Eigen::MatrixXd Ain;    // nin x n
  Eigen::VectorXd lbA, ubA;  // nin
  Eigen::VectorXd lb, ub;    // n
  // Optional structure hint: H = blkdiag(dense dense_block x dense_block, diagonal rest). 0 = dense H.
  int dense_block = 0;
  void resize(int n_, int neq_, int nin_);  // sets everything to zero / free bounds
};

enum class QpStatus {
  Optimal,
  Infeasible,        // the constraints admit no point
  IterationLimit,    // the iteration cap was hit: x is not a solution
  NumericalFailure,  // H not positive definite, dependent equalities, non-finite data, ...
};
const char* toString(QpStatus s);

struct QpSolution {
  QpStatus status = QpStatus::NumericalFailure;
  Eigen::VectorXd x;
  double objective = 0.0;
  int iterations = 0;       // working-set changes (additions + removals)
  // Active set at the solution, length n + nin: +1 active at upper, -1 at lower, 0 inactive
  // (the convention of docs/reference/qp-instances.md#file-format, active_ref). Equalities are always active and not listed.
  Eigen::VectorXi active;
  // Lagrange multipliers: equalities (neq), bounds (n) and rows (nin), signed so that
  //   H x + g = Aeq' y_eq + y_bounds + Ain' y_rows,
  // y > 0: the lower side binds, y < 0: the upper side binds, 0: inactive (fixed variables / lbA == ubA: any sign).
  Eigen::VectorXd y_eq, y_bounds, y_rows;
  // Sizes every vector for a problem of these dimensions (no allocation when the sizes already match).
  void resize(int n, int neq, int nin);
};

// Smallest k >= 1 such that H = blkdiag(H[0:k,0:k], diagonal): a value for QpProblem::dense_block (n if H is dense).
int detectDenseBlock(const Eigen::MatrixXd& H);

}  // namespace mft::qp
