#pragma once
// Independent reference for small QPs: enumerate active sets of the one-sided inequalities and solve each KKT
// system directly (full-pivot LU). A strictly convex feasible QP has a KKT point with independent active
// normals, so "no candidate passes" means infeasible. Exponential: only for tiny problems.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "wbc/qp/qp_problem.hpp"

namespace mft::qp::testing {

struct ReferenceResult {
  bool feasible = false;
  Eigen::VectorXd x;
};

inline ReferenceResult referenceSolve(const QpProblem& p, double tol = 1e-9) {
  const int n = p.n;
  // Equalities (Aeq, fixed bounds, lbA == ubA) and one-sided rows G x >= h.
  std::vector<Eigen::RowVectorXd> E, G;
  std::vector<double> e, h;
  for (int i = 0; i < p.neq; ++i) E.push_back(p.Aeq.row(i)), e.push_back(p.beq[i]);
  auto unit = [n](int j) { Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n); r[j] = 1.0; return r; };
  for (int j = 0; j < n; ++j) {
    if (p.lb[j] == p.ub[j]) { E.push_back(unit(j)); e.push_back(p.lb[j]); continue; }
    if (p.lb[j] > -kInf) G.push_back(unit(j)), h.push_back(p.lb[j]);
    if (p.ub[j] < kInf) G.push_back(-unit(j)), h.push_back(-p.ub[j]);
  }
  for (int i = 0; i < p.nin; ++i) {
    if (p.lbA[i] == p.ubA[i]) { E.push_back(p.Ain.row(i)); e.push_back(p.lbA[i]); continue; }
    if (p.lbA[i] > -kInf) G.push_back(p.Ain.row(i)), h.push_back(p.lbA[i]);
    if (p.ubA[i] < kInf) G.push_back(-p.Ain.row(i)), h.push_back(-p.ubA[i]);
  }
  // Keep a linearly independent subset of the equalities (greedy rank test); the others are checked at x.
  std::vector<Eigen::RowVectorXd> E_all = E;
  std::vector<double> e_all = e;
  E.clear();
  e.clear();
  for (std::size_t i = 0; i < E_all.size(); ++i) {
    Eigen::MatrixXd M(E.size() + 1, n);
    for (std::size_t r = 0; r < E.size(); ++r) M.row(r) = E[r];
    M.row(E.size()) = E_all[i];
    if (Eigen::FullPivLU<Eigen::MatrixXd>(M).rank() == static_cast<Eigen::Index>(E.size() + 1))
      E.push_back(E_all[i]), e.push_back(e_all[i]);
  }
  const int me = static_cast<int>(E.size()), mg = static_cast<int>(G.size());
  ReferenceResult res;
  for (int mask = 0; mask < (1 << mg); ++mask) {
    std::vector<int> S;
    for (int i = 0; i < mg; ++i)
      if (mask & (1 << i)) S.push_back(i);
    const int k = me + static_cast<int>(S.size());
    if (k > n) continue;
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + k, n + k);
    Eigen::VectorXd rhs(n + k);
    K.topLeftCorner(n, n) = p.H;
    rhs.head(n) = -p.g;
    for (int i = 0; i < k; ++i) {
      const Eigen::RowVectorXd& a = i < me ? E[i] : G[S[i - me]];
      K.block(n + i, 0, 1, n) = a;
      K.block(0, n + i, n, 1) = -a.transpose();
      rhs[n + i] = i < me ? e[i] : h[S[i - me]];
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    if (lu.rank() < n + k) continue;
    const Eigen::VectorXd sol = lu.solve(rhs);
    const Eigen::VectorXd x = sol.head(n);
    bool ok = true;
    for (int i = me; i < k && ok; ++i) ok = sol[n + i] >= -tol;
    for (std::size_t i = 0; i < E_all.size() && ok; ++i)
      ok = std::abs(E_all[i] * x - e_all[i]) <= tol * (1 + std::abs(e_all[i]));
    for (int i = 0; i < mg && ok; ++i) ok = G[i] * x - h[i] >= -tol * (1 + std::abs(h[i]));
    if (ok) {
      res.feasible = true;
      res.x = x;
      return res;
    }
  }
  return res;
}

// One-sided form of a QpProblem for the independent checks below: equalities E x = e (Aeq, fixed bounds,
// rows with lbA == ubA) and inequalities G x >= h (each finite side of a bound or row), with the index of the
// bound (0..n-1) or row (n..n+nin-1) each inequality came from and its side (-1 lower, +1 upper).
struct OneSidedForm {
  Eigen::MatrixXd E, G;
  Eigen::VectorXd e, h;
  std::vector<int> eq_source, in_source, in_side;
};

inline OneSidedForm oneSidedForm(const QpProblem& p) {
  const int n = p.n;
  std::vector<Eigen::RowVectorXd> E, G;
  OneSidedForm f;
  std::vector<double> e, h;
  auto unit = [n](int j) { Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n); r[j] = 1.0; return r; };
  for (int i = 0; i < p.neq; ++i) E.push_back(p.Aeq.row(i)), e.push_back(p.beq[i]), f.eq_source.push_back(-1);
  auto add = [&](const Eigen::RowVectorXd& a, double lo, double hi, int source) {
    if (lo == hi) {
      E.push_back(a), e.push_back(lo), f.eq_source.push_back(source);
      return;
    }
    if (lo > -kInf) G.push_back(a), h.push_back(lo), f.in_source.push_back(source), f.in_side.push_back(-1);
    if (hi < kInf) G.push_back(-a), h.push_back(-hi), f.in_source.push_back(source), f.in_side.push_back(+1);
  };
  for (int j = 0; j < n; ++j) add(unit(j), p.lb[j], p.ub[j], j);
  for (int i = 0; i < p.nin; ++i) add(p.Ain.row(i), p.lbA[i], p.ubA[i], n + i);
  f.E.resize(static_cast<Eigen::Index>(E.size()), n);
  f.G.resize(static_cast<Eigen::Index>(G.size()), n);
  f.e.resize(static_cast<Eigen::Index>(e.size()));
  f.h.resize(static_cast<Eigen::Index>(h.size()));
  for (std::size_t i = 0; i < E.size(); ++i) f.E.row(static_cast<Eigen::Index>(i)) = E[i], f.e[static_cast<Eigen::Index>(i)] = e[i];
  for (std::size_t i = 0; i < G.size(); ++i) f.G.row(static_cast<Eigen::Index>(i)) = G[i], f.h[static_cast<Eigen::Index>(i)] = h[i];
  return f;
}

struct InteriorPointResult {
  bool converged = false;
  int iterations = 0;
  Eigen::VectorXd x;
  double residual = 0.0;  // max of the scaled dual, equality and inequality residuals and the mean complementarity
  bool polished = false;  // x comes from the polishing step (see below)
};

// A dense primal-dual interior point method (Mehrotra predictor-corrector, infeasible start) for
//   min 1/2 x'Hx + g'x  s.t.  E x = e,  G x - s = h,  s >= 0.
// It shares nothing with the active-set solver under test: no working set, no factor updates, a fresh LU of the
// reduced Newton system every iteration. Slow (O(n^3) per iteration) and only meant for tests.
//
// Interior points need a feasible set with an interior. Fixed variables are therefore substituted out first, and
// a pair of inequalities that pins a combination from both sides (a x >= h and -a x >= -h, e.g. a swing foot's
// friction pyramid once its f_z = 0) becomes one equality.
inline InteriorPointResult interiorPointSolveReduced(const QpProblem& p, double tol, int max_iterations);

inline InteriorPointResult interiorPointSolve(const QpProblem& p, double tol = 1e-8, int max_iterations = 100) {
  std::vector<int> free_vars;
  Eigen::VectorXd fixed = Eigen::VectorXd::Zero(p.n);
  for (int j = 0; j < p.n; ++j) {
    if (p.lb[j] == p.ub[j]) fixed[j] = p.lb[j];
    else free_vars.push_back(j);
  }
  const int nf = static_cast<int>(free_vars.size());
  QpProblem r;
  r.resize(nf, p.neq, p.nin);
  for (int a = 0; a < nf; ++a) {
    const int ja = free_vars[static_cast<std::size_t>(a)];
    r.g[a] = p.g[ja] + p.H.row(ja).dot(fixed);
    r.lb[a] = p.lb[ja];
    r.ub[a] = p.ub[ja];
    r.Aeq.col(a) = p.Aeq.col(ja);
    r.Ain.col(a) = p.Ain.col(ja);
    for (int b = 0; b < nf; ++b) r.H(a, b) = p.H(ja, free_vars[static_cast<std::size_t>(b)]);
  }
  r.beq = p.beq - p.Aeq * fixed;
  const Eigen::VectorXd shift = p.Ain * fixed;
  r.lbA = p.lbA - shift;  // +-inf stay infinite
  r.ubA = p.ubA - shift;
  InteriorPointResult res = interiorPointSolveReduced(r, tol, max_iterations);
  Eigen::VectorXd x = fixed;
  for (int a = 0; a < nf; ++a) x[free_vars[static_cast<std::size_t>(a)]] = res.x[a];
  res.x = x;
  return res;
}

inline InteriorPointResult interiorPointSolveReduced(const QpProblem& p, double tol, int max_iterations) {
  OneSidedForm f = oneSidedForm(p);
  {
    // Mirrored pairs of inequalities -> equalities.
    std::vector<bool> merged(static_cast<std::size_t>(f.G.rows()), false);
    std::vector<Eigen::RowVectorXd> E_rows;
    std::vector<double> e_vals;
    for (Eigen::Index i = 0; i < f.E.rows(); ++i) E_rows.push_back(f.E.row(i)), e_vals.push_back(f.e[i]);
    for (Eigen::Index i = 0; i < f.G.rows(); ++i)
      for (Eigen::Index j = i + 1; j < f.G.rows() && !merged[static_cast<std::size_t>(i)]; ++j) {
        if (merged[static_cast<std::size_t>(j)]) continue;
        const double scale = 1.0 + f.G.row(i).cwiseAbs().maxCoeff();
        if ((f.G.row(i) + f.G.row(j)).cwiseAbs().maxCoeff() <= 1e-14 * scale &&
            std::abs(f.h[i] + f.h[j]) <= 1e-14 * (1.0 + std::abs(f.h[i]))) {
          merged[static_cast<std::size_t>(i)] = merged[static_cast<std::size_t>(j)] = true;
          E_rows.push_back(f.G.row(i)), e_vals.push_back(f.h[i]);
        }
      }
    Eigen::MatrixXd G(f.G.rows(), p.n);
    Eigen::VectorXd h(f.G.rows());
    Eigen::Index k = 0;
    for (Eigen::Index i = 0; i < f.G.rows(); ++i)
      if (!merged[static_cast<std::size_t>(i)]) G.row(k) = f.G.row(i), h[k++] = f.h[i];
    f.G = G.topRows(k);
    f.h = h.head(k);
    f.E.resize(static_cast<Eigen::Index>(E_rows.size()), p.n);
    f.e.resize(static_cast<Eigen::Index>(E_rows.size()));
    for (std::size_t i = 0; i < E_rows.size(); ++i)
      f.E.row(static_cast<Eigen::Index>(i)) = E_rows[i], f.e[static_cast<Eigen::Index>(i)] = e_vals[i];
  }
  const int n = p.n, me = static_cast<int>(f.E.rows()), mi = static_cast<int>(f.G.rows());
  InteriorPointResult res;
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_s, best_z;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), y = Eigen::VectorXd::Zero(me);
  Eigen::VectorXd s = (f.G * x - f.h).cwiseMax(1.0), z = Eigen::VectorXd::Ones(mi);
  const double scale_d = 1.0 + p.g.cwiseAbs().maxCoeff(), scale_e = 1.0 + (me ? f.e.cwiseAbs().maxCoeff() : 0.0),
               scale_i = 1.0 + (mi ? f.h.cwiseAbs().maxCoeff() : 0.0);
  auto stepTo = [](const Eigen::VectorXd& v, const Eigen::VectorXd& dv) {
    double a = 1.0;
    for (int i = 0; i < v.size(); ++i)
      if (dv[i] < 0.0) a = std::min(a, -v[i] / dv[i]);
    return a;
  };
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::VectorXd r_d = p.H * x + p.g - f.E.transpose() * y - f.G.transpose() * z;
    const Eigen::VectorXd r_e = f.E * x - f.e;
    const Eigen::VectorXd r_i = f.G * x - s - f.h;
    const double mu = mi ? s.dot(z) / mi : 0.0;
    const bool finite = x.allFinite() && y.allFinite() && s.allFinite() && z.allFinite();
    const double residual =
        finite ? std::max({r_d.cwiseAbs().maxCoeff() / scale_d, me ? r_e.cwiseAbs().maxCoeff() / scale_e : 0.0,
                           mi ? r_i.cwiseAbs().maxCoeff() / scale_i : 0.0, mu})
               : std::numeric_limits<double>::infinity();
    // Keep the best iterate: close to the solution the Newton system gets ill-conditioned (z / s spans many
    // orders of magnitude) and later iterates can be slightly worse.
    if (residual < best) best = residual, res.x = x, res.iterations = it, best_s = s, best_z = z;
    if (residual <= tol || !finite) break;
    // Reduced Newton system [H + G' S^-1 Z G, -E'; E, 0] [dx; dy] = rhs, shared by predictor and corrector.
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + me, n + me);
    const Eigen::VectorXd zs = z.cwiseQuotient(s);
    K.topLeftCorner(n, n) = p.H + f.G.transpose() * zs.asDiagonal() * f.G;
    K.topRightCorner(n, me) = -f.E.transpose();
    K.bottomLeftCorner(me, n) = f.E;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    auto direction = [&](const Eigen::VectorXd& r_c, Eigen::VectorXd* dx, Eigen::VectorXd* dy, Eigen::VectorXd* ds,
                         Eigen::VectorXd* dz) {
      Eigen::VectorXd rhs(n + me);
      rhs.head(n) = -r_d - f.G.transpose() * (r_c + z.cwiseProduct(r_i)).cwiseQuotient(s);
      rhs.tail(me) = -r_e;
      const Eigen::VectorXd d = lu.solve(rhs);
      *dx = d.head(n);
      *dy = d.tail(me);
      *ds = f.G * *dx + r_i;
      *dz = -(r_c + z.cwiseProduct(*ds)).cwiseQuotient(s);
    };
    Eigen::VectorXd dx, dy, ds, dz;
    direction(s.cwiseProduct(z), &dx, &dy, &ds, &dz);  // affine scaling (predictor)
    const double a_aff = std::min(stepTo(s, ds), stepTo(z, dz));
    const double mu_aff = mi ? (s + a_aff * ds).dot(z + a_aff * dz) / mi : 0.0;
    const double sigma = mu > 0.0 ? std::pow(mu_aff / mu, 3) : 0.0;
    const Eigen::VectorXd r_c = s.cwiseProduct(z) + ds.cwiseProduct(dz) - Eigen::VectorXd::Constant(mi, sigma * mu);
    direction(r_c, &dx, &dy, &ds, &dz);  // corrector
    const double a = std::min(1.0, 0.995 * std::min(stepTo(s, ds), stepTo(z, dz)));
    x += a * dx;
    y += a * dy;
    s += a * ds;
    z += a * dz;
  }
  res.residual = best;
  res.converged = best <= tol;
  if (res.x.size() != n) res.x = x;
  if (!(best <= 1e3 * tol)) return res;
  // Polish (crossover): the inequalities the interior point found binding (z > s) held as equalities, the
  // equality-constrained KKT system solved directly. Kept only if the result is feasible with non-negative
  // multipliers; it removes the interior point's error along the directions where the cost is nearly flat.
  std::vector<int> binding;
  for (int i = 0; i < mi; ++i)
    if (best_z[i] > best_s[i]) binding.push_back(i);
  const int m = me + static_cast<int>(binding.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  Eigen::VectorXd rhs(n + m);
  K.topLeftCorner(n, n) = p.H;
  rhs.head(n) = -p.g;
  for (int i = 0; i < m; ++i) {
    const bool eq = i < me;
    const Eigen::RowVectorXd a = eq ? Eigen::RowVectorXd(f.E.row(i)) : Eigen::RowVectorXd(f.G.row(binding[static_cast<std::size_t>(i - me)]));
    K.block(n + i, 0, 1, n) = a;
    K.block(0, n + i, n, 1) = -a.transpose();
    rhs[n + i] = eq ? f.e[i] : f.h[binding[static_cast<std::size_t>(i - me)]];
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
  if (lu.rank() < n + m) return res;
  const Eigen::VectorXd sol = lu.solve(rhs);
  const Eigen::VectorXd xp = sol.head(n);
  bool ok = sol.allFinite();
  for (int i = me; i < m && ok; ++i) ok = sol[n + i] >= -1e-9 * scale_d;
  if (mi) ok = ok && (f.G * xp - f.h).minCoeff() >= -1e-9 * scale_i;
  if (me) ok = ok && (f.E * xp - f.e).cwiseAbs().maxCoeff() <= 1e-9 * scale_e;
  if (ok) res.x = xp, res.polished = true;
  return res;
}

struct ActiveSetCheck {
  bool solvable = false;  // the KKT matrix of the active set is nonsingular
  Eigen::VectorXd x;      // the minimizer with every listed constraint held as an equality
  QpSolution solution;    // x and the multipliers in the convention of qp_problem.hpp (for kktResiduals)
  double worst_sign = 0.0;  // most negative "right-sign" multiplier (<= 0 means a sign violation of that size)
};

// Active-set verification: holds the equalities and every constraint that `active` (length n + nin, +1 upper,
// -1 lower, 0 free) lists as equalities, solves that equality-constrained KKT system directly and returns x and
// the multipliers. x is the QP's minimizer iff it satisfies the other constraints and the multipliers have the
// right signs, which the caller checks (kktResiduals). Fixed bounds and rows with lbA == ubA are equalities
// whatever `active` says about them.
inline ActiveSetCheck activeSetSolve(const QpProblem& p, const Eigen::VectorXi& active) {
  const int n = p.n;
  std::vector<Eigen::RowVectorXd> rows;
  std::vector<double> rhs;
  std::vector<int> source;  // -1 - i for Aeq row i, else the bound/row index
  for (int i = 0; i < p.neq; ++i) rows.push_back(p.Aeq.row(i)), rhs.push_back(p.beq[i]), source.push_back(-1 - i);
  for (int k = 0; k < n + p.nin; ++k) {
    const bool bound = k < n;
    const double lo = bound ? p.lb[k] : p.lbA[k - n], hi = bound ? p.ub[k] : p.ubA[k - n];
    const int side = lo == hi ? -1 : active[k];
    if (side == 0) continue;
    Eigen::RowVectorXd a = Eigen::RowVectorXd::Zero(n);
    if (bound) a[k] = 1.0;
    else a = p.Ain.row(k - n);
    rows.push_back(a), rhs.push_back(side < 0 ? lo : hi), source.push_back(k);
  }
  const int m = static_cast<int>(rows.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  Eigen::VectorXd b(n + m);
  K.topLeftCorner(n, n) = p.H;
  b.head(n) = -p.g;
  for (int i = 0; i < m; ++i) {
    K.block(n + i, 0, 1, n) = rows[static_cast<std::size_t>(i)];
    K.block(0, n + i, n, 1) = -rows[static_cast<std::size_t>(i)].transpose();
    b[n + i] = rhs[static_cast<std::size_t>(i)];
  }
  ActiveSetCheck c;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
  if (lu.rank() < n + m) return c;
  c.solvable = true;
  const Eigen::VectorXd sol = lu.solve(b);
  c.x = sol.head(n);
  QpSolution& out = c.solution;
  out.status = QpStatus::Optimal;
  out.x = c.x;
  out.y_eq = Eigen::VectorXd::Zero(p.neq);
  out.y_bounds = Eigen::VectorXd::Zero(n);
  out.y_rows = Eigen::VectorXd::Zero(p.nin);
  out.active = active;
  for (int i = 0; i < m; ++i) {
    const double y = sol[n + i];
    const int k = source[static_cast<std::size_t>(i)];
    if (k < 0) {
      out.y_eq[-1 - k] = y;
      continue;
    }
    (k < n ? out.y_bounds[k] : out.y_rows[k - n]) = y;
    const double lo = k < n ? p.lb[k] : p.lbA[k - n], hi = k < n ? p.ub[k] : p.ubA[k - n];
    if (lo != hi) c.worst_sign = std::min(c.worst_sign, active[k] < 0 ? y : -y);
  }
  return c;
}

// Random strictly convex H = blkdiag(dense k x k, positive diagonal) (k = n: dense).
inline Eigen::MatrixXd randomBlockH(int n, int k, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.2, 3.0);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd M(k, k);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) M(i, j) = N(rng);
  H.topLeftCorner(k, k) = M * M.transpose() + 0.1 * Eigen::MatrixXd::Identity(k, k);
  for (int j = k; j < n; ++j) H(j, j) = U(rng);
  return H;
}

}  // namespace mft::qp::testing
