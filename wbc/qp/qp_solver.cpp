#include "wbc/qp/qp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mft::qp {
namespace {

constexpr double kNoStep = std::numeric_limits<double>::infinity();

bool noNaN(const Eigen::VectorXd& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::isnan(v[i])) return false;
  return true;
}

// All entries finite: x * 0 is 0 for finite x and NaN otherwise; the sum vectorizes without branches.
template <class M>
bool allFinite(const M& m) {
  return (m.array() * 0.0).sum() == 0.0;
}

}  // namespace

GoldfarbIdnaniSolver::GoldfarbIdnaniSolver(int n, int neq, int nin, const GoldfarbIdnaniOptions& options)
    : options_(options) {
  resize(n, neq, nin);
}

void GoldfarbIdnaniSolver::resize(int n, int neq, int nin) {
  n_ = n;
  neq_ = neq;
  nin_ = nin;
  L_.setZero(n, n);
  J_.setZero(n, n);
  R_.setZero(n, n);
  for (Eigen::VectorXd* v : {&x_, &x_unc_, &d_, &r_, &u_, &w_, &np_}) v->setZero(n);
  row_values_.setZero(nin);
  lo_.assign(n, 0);
  hi_.assign(n, 0);
  const int m_cap = neq + 2 * n + 2 * nin;
  kind_.assign(m_cap, kEqRow);
  index_.assign(m_cap, 0);
  sign_.assign(m_cap, 1.0);
  bound_.assign(m_cap, 0.0);
  in_active_.assign(m_cap, 0);
  dependent_.assign(neq + n + nin, 0);
  active_.assign(n, 0);  // active normals are independent: at most n
  warm_keys_.assign(n, 0);
  warm_count_ = 0;
  key_to_constraint_.assign(2 * n + 2 * nin, -1);
}

QpStatus GoldfarbIdnaniSolver::solve(const QpProblem& p, QpSolution* sol) {
  if (p.n != n_ || p.neq != neq_ || p.nin != nin_) resize(p.n, p.neq, p.nin);
  sol->resize(p.n, p.neq, p.nin);
  last_warm_ = last_fallback_ = false;
  iterate_valid_ = false;
  QpStatus status = checkData(p);
  if (status == QpStatus::Optimal) {
    const bool warm = options_.warm_start && warm_count_ > 0;
    last_warm_ = warm;
    status = solveOnce(p, warm);
    // A warm start only changes the path; if that path fails, the cold one decides.
    if (warm && status != QpStatus::Optimal) {
      last_fallback_ = true;
      status = solveOnce(p, false);
    }
  }
  if (status == QpStatus::Optimal)
    rememberActiveSet();
  else
    warm_count_ = 0;
  writeSolution(p, status, sol);
  return status;
}

QpStatus GoldfarbIdnaniSolver::checkData(const QpProblem& p) const {
  const int n = p.n;
  if (p.H.rows() != n || p.H.cols() != n || p.g.size() != n || p.Aeq.rows() != p.neq || p.Aeq.cols() != n ||
      p.beq.size() != p.neq || p.Ain.rows() != p.nin || p.Ain.cols() != n || p.lbA.size() != p.nin ||
      p.ubA.size() != p.nin || p.lb.size() != n || p.ub.size() != n)
    return QpStatus::NumericalFailure;
  if (!allFinite(p.H) || !allFinite(p.g) || !allFinite(p.Aeq) || !allFinite(p.beq) || !allFinite(p.Ain))
    return QpStatus::NumericalFailure;
  if (!noNaN(p.lb) || !noNaN(p.ub) || !noNaN(p.lbA) || !noNaN(p.ubA)) return QpStatus::NumericalFailure;
  for (int j = 0; j < n; ++j)
    if (p.lb[j] > p.ub[j] || p.lb[j] == kInf || p.ub[j] == -kInf) return QpStatus::Infeasible;
  for (int i = 0; i < p.nin; ++i)
    if (p.lbA[i] > p.ubA[i] || p.lbA[i] == kInf || p.ubA[i] == -kInf) return QpStatus::Infeasible;
  return QpStatus::Optimal;
}

bool GoldfarbIdnaniSolver::factorize(const QpProblem& p) {
  const int n = n_;
  const Eigen::MatrixXd& H = p.H;
  int nb = p.dense_block;
  if (nb <= 0 || nb > n) nb = n;
  // Trust the hint only if the lower triangle outside the block is really diagonal.
  for (int j = 0; j < n && nb < n; ++j)
    for (int i = std::max(j + 1, nb); i < n; ++i)
      if (H(i, j) != 0.0) {
        nb = n;
        break;
      }
  nb_ = nb;
  J_.setZero();

  // Cholesky H[0:nb,0:nb] = L L' (lower triangle read), then J = L^-T (upper triangular) column by column.
  for (int j = 0; j < nb; ++j) {
    double s = H(j, j);
    for (int k = 0; k < j; ++k) s -= L_(j, k) * L_(j, k);
    if (!(s > 1e-14 * std::abs(H(j, j))) || !(s > 0.0)) return false;
    const double ljj = std::sqrt(s);
    L_(j, j) = ljj;
    for (int i = j + 1; i < nb; ++i) {
      double v = H(i, j);
      for (int k = 0; k < j; ++k) v -= L_(i, k) * L_(j, k);
      L_(i, j) = v / ljj;
    }
  }
  for (int j = 0; j < nb; ++j) {
    double* Jj = &J_(0, j);
    Jj[j] = 1.0 / L_(j, j);
    for (int i = j - 1; i >= 0; --i) {
      const double* Li = &L_(0, i);
      double v = 0.0;
      for (int k = i + 1; k <= j; ++k) v += Li[k] * Jj[k];
      Jj[i] = -v / Li[i];
    }
  }
  for (int j = nb; j < n; ++j) {
    if (!(H(j, j) > 0.0)) return false;
    J_(j, j) = 1.0 / std::sqrt(H(j, j));
  }
  for (int j = 0; j < n; ++j) {
    lo_[j] = j < nb ? 0 : j;
    hi_[j] = j + 1;
  }

  // Unconstrained minimizer x_unc = -J J' g (the sign matters: eiquadprog's provided-factor path misses it).
  for (int j = 0; j < nb; ++j) w_[j] = J_.col(j).head(j + 1).dot(p.g.head(j + 1));
  for (int j = nb; j < n; ++j) w_[j] = J_(j, j) * p.g[j];
  x_unc_.head(nb).noalias() = -J_.topLeftCorner(nb, nb) * w_.head(nb);
  for (int j = nb; j < n; ++j) x_unc_[j] = -J_(j, j) * w_[j];
  return true;
}

void GoldfarbIdnaniSolver::buildConstraints(const QpProblem& p) {
  int m = 0;
  auto push = [&](Kind kind, int index, double sign, double bound) {
    kind_[m] = kind;
    index_[m] = index;
    sign_[m] = sign;
    bound_[m] = bound;
    in_active_[m] = 0;
    return m++;
  };
  // Always active: equalities, fixed variables, rows with lbA == ubA.
  for (int i = 0; i < p.neq; ++i) push(kEqRow, i, 1.0, p.beq[i]);
  for (int j = 0; j < p.n; ++j)
    if (p.lb[j] == p.ub[j]) push(kBound, j, 1.0, p.lb[j]);
  for (int i = 0; i < p.nin; ++i)
    if (p.lbA[i] == p.ubA[i]) push(kRow, i, 1.0, p.lbA[i]);
  m_always_ = m;
  std::fill(key_to_constraint_.begin(), key_to_constraint_.end(), -1);
  for (int j = 0; j < p.n; ++j) {
    if (p.lb[j] == p.ub[j]) continue;
    if (p.lb[j] > -kInf) key_to_constraint_[2 * j] = push(kBound, j, 1.0, p.lb[j]);
    if (p.ub[j] < kInf) key_to_constraint_[2 * j + 1] = push(kBound, j, -1.0, -p.ub[j]);
  }
  for (int i = 0; i < p.nin; ++i) {
    if (p.lbA[i] == p.ubA[i]) continue;
    if (p.lbA[i] > -kInf) key_to_constraint_[2 * n_ + 2 * i] = push(kRow, i, 1.0, p.lbA[i]);
    if (p.ubA[i] < kInf) key_to_constraint_[2 * n_ + 2 * i + 1] = push(kRow, i, -1.0, -p.ubA[i]);
  }
  m_ = m;
}

void GoldfarbIdnaniSolver::computeD(const QpProblem& p, int c) {
  const double sign = sign_[c];
  const int idx = index_[c];
  if (kind_[c] == kBound) {
    // Unit normal: J' e_idx is row idx of J, no mat-vec.
    for (int k = 0; k < n_; ++k) d_[k] = sign * J_(idx, k);
    return;
  }
  const Eigen::MatrixXd& A = kind_[c] == kEqRow ? p.Aeq : p.Ain;
  np_.noalias() = sign * A.row(idx).transpose();
  const double* nv = np_.data();
  for (int j = 0; j < n_; ++j) {
    const double* Jj = &J_(0, j);
    double v = 0.0;
    for (int k = lo_[j]; k < hi_[j]; ++k) v += Jj[k] * nv[k];
    d_[j] = v;
  }
}

void GoldfarbIdnaniSolver::rotateColumns(int a, int b, double c, double s) {
  // Only the union of the two columns' nonzero row ranges changes; entries outside stay exactly zero.
  const int lo = std::min(lo_[a], lo_[b]), hi = std::max(hi_[a], hi_[b]);
  lo_[a] = lo_[b] = lo;
  hi_[a] = hi_[b] = hi;
  double* A = &J_(0, a);
  double* B = &J_(0, b);
  for (int k = lo; k < hi; ++k) {
    const double ta = A[k], tb = B[k];
    A[k] = c * ta + s * tb;
    B[k] = c * tb - s * ta;
  }
}

double GoldfarbIdnaniSolver::slack(const QpProblem& p, int c) const {
  const int idx = index_[c];
  double v;
  switch (kind_[c]) {
    case kBound: v = x_[idx]; break;
    case kRow: v = row_values_[idx]; break;
    default: v = p.Aeq.row(idx).dot(x_); break;
  }
  return sign_[c] * v - bound_[c];
}

bool GoldfarbIdnaniSolver::isDependent() const {
  const double outside = d_.tail(n_ - q_).squaredNorm();
  const double total = outside + d_.head(q_).squaredNorm();
  const double tol = options_.dependence_tol;
  return !(outside > tol * tol * total);
}

void GoldfarbIdnaniSolver::addToFactor(int c) {
  // Rotate d = J'n so that only its first q+1 entries are nonzero; R gets d[0..q] as its new column.
  // Each nonzero d[i] is rotated straight into d[q]: columns with d[i] == 0 (e.g. the eps columns a row does
  // not touch) are left alone, which a chain of adjacent rotations would not do.
  const int q = q_;
  for (int i = q + 1; i < n_; ++i) {
    const double b = d_[i];
    if (b == 0.0) continue;
    const double a = d_[q];
    const double h = std::sqrt(a * a + b * b);
    d_[q] = h;
    d_[i] = 0.0;
    rotateColumns(q, i, a / h, b / h);
  }
  R_.col(q_).head(q_ + 1) = d_.head(q_ + 1);
  active_[q_] = c;
  in_active_[c] = 1;
  ++q_;
}

void GoldfarbIdnaniSolver::dropFromFactor(int pos) {
  in_active_[active_[pos]] = 0;
  for (int j = pos; j + 1 < q_; ++j) {
    active_[j] = active_[j + 1];
    u_[j] = u_[j + 1];
    R_.col(j).head(j + 2) = R_.col(j + 1).head(j + 2);
  }
  --q_;
  // R is now upper Hessenberg from column pos on: rotate rows (j, j+1) back to triangular, J columns along.
  for (int j = pos; j < q_; ++j) {
    const double a = R_(j, j), b = R_(j + 1, j);
    if (b == 0.0) continue;
    const double h = std::sqrt(a * a + b * b);
    const double cs = a / h, sn = b / h;
    R_(j, j) = h;
    R_(j + 1, j) = 0.0;
    for (int l = j + 1; l < q_; ++l) {
      const double ta = R_(j, l), tb = R_(j + 1, l);
      R_(j, l) = cs * ta + sn * tb;
      R_(j + 1, l) = cs * tb - sn * ta;
    }
    rotateColumns(j, j + 1, cs, sn);
  }
}

void GoldfarbIdnaniSolver::primalDualFromFactor(const QpProblem& p) {
  // With J' N = [R; 0]:  x = x_unc + J1 R^-T (b - N' x_unc),  u = R^-1 R^-T (b - N' x_unc).
  const int q = q_;
  for (int j = 0; j < q; ++j) {
    const int c = active_[j], idx = index_[c];
    double v;
    switch (kind_[c]) {
      case kBound: v = x_unc_[idx]; break;
      case kRow: v = p.Ain.row(idx).dot(x_unc_); break;
      default: v = p.Aeq.row(idx).dot(x_unc_); break;
    }
    double e = bound_[c] - sign_[c] * v;
    const double* Rj = &R_(0, j);
    for (int i = 0; i < j; ++i) e -= Rj[i] * w_[i];
    w_[j] = e / Rj[j];
  }
  x_ = x_unc_;
  for (int j = 0; j < q; ++j) {
    const double* Jj = &J_(0, j);
    const double wj = w_[j];
    for (int k = lo_[j]; k < hi_[j]; ++k) x_[k] += wj * Jj[k];
  }
  for (int j = q - 1; j >= 0; --j) {
    double v = w_[j];
    for (int k = j + 1; k < q; ++k) v -= R_(j, k) * u_[k];
    u_[j] = v / R_(j, j);
  }
}

QpStatus GoldfarbIdnaniSolver::solveOnce(const QpProblem& p, bool warm) {
  iterations_ = 0;
  q_ = 0;
  n_dependent_ = 0;
  if (!factorize(p)) return QpStatus::NumericalFailure;
  buildConstraints(p);
  iterate_valid_ = true;

  for (int c = 0; c < m_always_; ++c) {
    computeD(p, c);
    if (isDependent())
      dependent_[n_dependent_++] = c;  // redundant if consistent: checked below
    else
      addToFactor(c);
  }
  q_always_ = q_;
  if (warm) {
    for (int k = 0; k < warm_count_; ++k) {
      const int c = key_to_constraint_[warm_keys_[k]];
      if (c < 0 || in_active_[c]) continue;
      computeD(p, c);
      if (isDependent()) continue;
      addToFactor(c);
      ++iterations_;
    }
  }
  primalDualFromFactor(p);
  if (warm) {
    // GI needs a dual-feasible start: drop the most negative inequality multiplier until none is left.
    for (;;) {
      int worst = -1;
      double most_negative = 0.0;
      for (int j = q_always_; j < q_; ++j)
        if (u_[j] < most_negative) most_negative = u_[j], worst = j;
      if (worst < 0) break;
      dropFromFactor(worst);
      ++iterations_;
      primalDualFromFactor(p);
    }
  }
  if (!x_.allFinite()) return QpStatus::NumericalFailure;
  // Dependent equalities hold everywhere on the affine set of the others, or never.
  for (int k = 0; k < n_dependent_; ++k) {
    const int c = dependent_[k];
    if (kind_[c] == kRow) row_values_[index_[c]] = p.Ain.row(index_[c]).dot(x_);
    if (std::abs(slack(p, c)) > options_.feasibility_tol * (1.0 + std::abs(bound_[c]))) return QpStatus::Infeasible;
  }

  const double tol = options_.feasibility_tol;
  for (;;) {
    // Slacks are recomputed once per added constraint: every addition moves x, so an incremental update
    // would cost the same mat-vec (Ain z) and accumulate rounding.
    row_values_.noalias() = p.Ain * x_;
    int cp = -1;
    double sp = 0.0;
    for (int c = m_always_; c < m_; ++c) {
      if (in_active_[c]) continue;
      const double s = slack(p, c);
      if (s < -tol * (1.0 + std::abs(bound_[c])) && s < sp) sp = s, cp = c;
    }
    if (cp < 0) return QpStatus::Optimal;
    if (iterations_ >= options_.max_iterations) return QpStatus::IterationLimit;

    double up = 0.0;  // multiplier of the constraint being added
    for (;;) {
      computeD(p, cp);
      const int q = q_;
      const double d2sq = d_.tail(n_ - q).squaredNorm();  // = z' n_p
      const bool dependent = isDependent();
      // r = R^-1 d1: how the active multipliers change per unit of the new one.
      for (int j = q - 1; j >= 0; --j) {
        double v = d_[j];
        for (int k = j + 1; k < q; ++k) v -= R_(j, k) * r_[k];
        r_[j] = v / R_(j, j);
      }
      double t1 = kNoStep;  // largest dual step keeping the active inequality multipliers >= 0
      int k_drop = -1;
      for (int j = q_always_; j < q; ++j)
        if (r_[j] > 0.0) {
          const double t = u_[j] / r_[j];
          if (t < t1) t1 = t, k_drop = j;
        }
      const double t2 = dependent ? kNoStep : -sp / d2sq;  // full step: makes the constraint active
      if (t1 == kNoStep && t2 == kNoStep) return QpStatus::Infeasible;
      const double t = std::min(t1, t2);
      if (t2 != kNoStep) {
        // Primal step along z = J2 J2' n_p.
        for (int j = q; j < n_; ++j) {
          const double* Jj = &J_(0, j);
          const double step = t * d_[j];
          if (step == 0.0) continue;
          for (int k = lo_[j]; k < hi_[j]; ++k) x_[k] += step * Jj[k];
        }
        sp += t * d2sq;
      }
      for (int j = 0; j < q; ++j) u_[j] -= t * r_[j];
      up += t;
      ++iterations_;
      if (t2 <= t1) {
        u_[q] = up;
        addToFactor(cp);  // d_ is still J' n_p for the current J
        break;
      }
      u_[k_drop] = 0.0;
      dropFromFactor(k_drop);
      if (iterations_ >= options_.max_iterations) return QpStatus::IterationLimit;
    }
    if (!x_.allFinite()) return QpStatus::NumericalFailure;
  }
}

void GoldfarbIdnaniSolver::rememberActiveSet() {
  warm_count_ = 0;
  for (int j = q_always_; j < q_; ++j) {
    const int c = active_[j];
    const int base = kind_[c] == kBound ? 2 * index_[c] : 2 * n_ + 2 * index_[c];
    warm_keys_[warm_count_++] = base + (sign_[c] < 0.0 ? 1 : 0);
  }
}

void GoldfarbIdnaniSolver::writeSolution(const QpProblem& p, QpStatus status, QpSolution* sol) const {
  sol->status = status;
  sol->iterations = iterations_;
  sol->y_eq.setZero();
  sol->y_bounds.setZero();
  sol->y_rows.setZero();
  sol->active.setZero();
  if (!iterate_valid_ || status == QpStatus::NumericalFailure) {  // no meaningful iterate to report
    sol->x.setConstant(std::numeric_limits<double>::quiet_NaN());
    sol->objective = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  sol->x = x_;
  // Fixed variables and lbA == ubA rows are reported at +1 (qpOASES's convention in active_ref).
  for (int c = 0; c < m_always_; ++c) {
    if (kind_[c] == kBound) sol->active[index_[c]] = 1;
    if (kind_[c] == kRow) sol->active[n_ + index_[c]] = 1;
  }
  for (int j = 0; j < q_; ++j) {
    const int c = active_[j], idx = index_[c];
    const double y = sign_[c] * u_[j];
    const bool always = c < m_always_;
    switch (kind_[c]) {
      case kEqRow: sol->y_eq[idx] = y; break;
      case kBound:
        sol->y_bounds[idx] = y;
        if (!always) sol->active[idx] = sign_[c] > 0.0 ? -1 : 1;
        break;
      case kRow:
        sol->y_rows[idx] = y;
        if (!always) sol->active[n_ + idx] = sign_[c] > 0.0 ? -1 : 1;
        break;
    }
  }
  // Objective with the block structure of H: dense block plus diagonal.
  const int nb = nb_;
  double f = p.g.dot(x_);
  double quad = 0.0;
  for (int j = 0; j < nb; ++j) quad += x_[j] * p.H.col(j).head(nb).dot(x_.head(nb));
  f += 0.5 * quad;
  for (int j = nb; j < n_; ++j) f += 0.5 * p.H(j, j) * x_[j] * x_[j];
  sol->objective = f;
}

}  // namespace mft::qp
