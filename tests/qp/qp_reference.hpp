#pragma once
// Independent reference for small QPs: enumerate active sets of the one-sided inequalities and solve each KKT
// system directly (full-pivot LU). A strictly convex feasible QP has a KKT point with independent active
// normals, so "no candidate passes" means infeasible. Exponential: only for tiny problems.
#include <Eigen/Dense>
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
