#pragma once
// Dense Goldfarb–Idnani dual active-set solver for QpProblem (docs/reference/qp.md).
//
// Method: H = L L', J = L^-T. Start at the unconstrained minimizer x0 = -J J' g, add the equalities (always
// active), then repeatedly add the most violated inequality, taking primal/dual steps that keep every active
// inequality multiplier >= 0 and dropping constraints whose multiplier reaches 0. The active normals N are
// kept as J' N = [R; 0] (R upper triangular) with Givens updates of J and R.
//
// Internally every finite side of a bound or row is one one-sided row  n'x >= b. Fixed variables (lb == ub)
// and rows with lbA == ubA are equalities (always active). Bounds are unit-normal rows: their J' n is a row of J.
// H = blkdiag(dense k x k, diagonal) via QpProblem::dense_block is factorized block-wise.
//
// Real-time use: construct with the problem dimensions (or call resize()); solve() then allocates nothing as
// long as the problem has those dimensions and the QpSolution was sized before (QpSolution::resize, or solve()
// sizes it on its first call). A problem with other dimensions makes solve() resize (allocates) once.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "wbc/qp/qp_problem.hpp"

namespace mft::qp {

struct GoldfarbIdnaniOptions {
  int max_iterations = 200;        // cap on working-set changes (additions + removals) per solve
  bool warm_start = false;         // start from the previous optimal active set (re-added, wrong signs dropped)
  double feasibility_tol = 1e-9;   // a side is violated when its slack < -tol * (1 + |bound|)
  double dependence_tol = 1e-10;   // a normal is linearly dependent on the active ones when
                                   // |part of J'n outside the active range| <= tol * |J'n|
};

class GoldfarbIdnaniSolver {
 public:
  GoldfarbIdnaniSolver() = default;
  GoldfarbIdnaniSolver(int n, int neq, int nin, const GoldfarbIdnaniOptions& options = {});

  // Sizes all storage for problems of these dimensions (allocates) and forgets the warm-start set.
  void resize(int n, int neq, int nin);
  GoldfarbIdnaniOptions& options() { return options_; }
  const GoldfarbIdnaniOptions& options() const { return options_; }

  // Solves the problem; the status is also stored in solution->status. Never use x unless it is Optimal.
  // With warm_start, a warm solve that does not end Optimal/Infeasible is repeated cold within this call.
  QpStatus solve(const QpProblem& problem, QpSolution* solution);

  // Forgets the previous active set: the next solve is cold.
  void clearWarmStart() { warm_count_ = 0; }
  // Whether the last solve() started from a previous active set, and whether it had to fall back to cold.
  bool lastSolveWasWarm() const { return last_warm_; }
  bool lastSolveFellBack() const { return last_fallback_; }

  int n() const { return n_; }
  int neq() const { return neq_; }
  int nin() const { return nin_; }

 private:
  enum Kind : std::uint8_t { kEqRow, kBound, kRow };

  QpStatus solveOnce(const QpProblem& p, bool warm);
  QpStatus checkData(const QpProblem& p) const;
  bool factorize(const QpProblem& p);  // J = L^-T, x_unc; false if H is not positive definite
  void buildConstraints(const QpProblem& p);
  void computeD(const QpProblem& p, int c);  // d = J' n_c
  double slack(const QpProblem& p, int c) const;
  void rotateColumns(int a, int b, double c, double s);  // Givens rotation of J columns a, b
  void addToFactor(int c);                   // uses d_; appends c to the active set
  void dropFromFactor(int pos);              // removes active position pos
  void primalDualFromFactor(const QpProblem& p);  // x, u for the active set taken as equalities
  bool isDependent() const;                  // of d_ on the active normals
  void writeSolution(const QpProblem& p, QpStatus status, QpSolution* sol) const;
  void rememberActiveSet();

  GoldfarbIdnaniOptions options_;
  int n_ = 0, neq_ = 0, nin_ = 0;
  int nb_ = 0;  // size of the dense leading block of H in this solve

  Eigen::MatrixXd L_;  // Cholesky factor of the dense block
  Eigen::MatrixXd J_;  // n x n, J J' = H^-1, columns [active range | rest]
  Eigen::MatrixXd R_;  // upper triangular, q x q used
  std::vector<int> lo_, hi_;  // rows [lo, hi) of each J column that may be nonzero (block structure)
  Eigen::VectorXd x_, x_unc_, d_, r_, u_, w_, np_, row_values_;

  // Internal one-sided constraints n'x >= b: the always-active ones first, then the inequalities.
  std::vector<Kind> kind_;
  std::vector<int> index_;
  std::vector<double> sign_;  // n = sign * (row of Aeq / e_index / row of Ain)
  std::vector<double> bound_;
  std::vector<char> in_active_;
  int m_ = 0, m_always_ = 0;
  std::vector<int> dependent_;  // always-active constraints skipped as dependent (checked for consistency)
  int n_dependent_ = 0;

  std::vector<int> active_;  // internal constraint of each active position
  int q_ = 0;                // active positions in use
  int q_always_ = 0;         // of which always-active (the leading positions)
  int iterations_ = 0;

  // Warm start: keys (2*var + upper, or 2n + 2*row + upper) of the last optimal active inequalities.
  std::vector<int> warm_keys_;
  int warm_count_ = 0;
  std::vector<int> key_to_constraint_;
  bool last_warm_ = false, last_fallback_ = false;
  bool iterate_valid_ = false;  // x_ belongs to this solve
};

}  // namespace mft::qp
