// Random QPs against the independent active-set enumeration of qp_reference.hpp: feasible, infeasible,
// degenerate (redundant / duplicated rows, fixed variables with rows through them), bounds-only,
// equality-only, dependent equalities; cold and warm.
#include <gtest/gtest.h>

#include "qp_reference.hpp"
#include "wbc/qp/qp_kkt.hpp"
#include "wbc/qp/qp_solver.hpp"

using namespace mft::qp;
using mft::qp::testing::randomBlockH;
using mft::qp::testing::referenceSolve;

namespace {

struct Shape {
  int n, neq, nin;
  bool bounds;
};

// A random problem; with `feasible` the constraints are built around a point, otherwise they are arbitrary.
QpProblem randomProblem(const Shape& s, bool feasible, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  QpProblem p;
  p.resize(s.n, s.neq, s.nin);
  const int k = 1 + static_cast<int>(rng() % s.n);
  p.H = randomBlockH(s.n, k, rng);
  p.dense_block = (rng() % 2) ? k : 0;
  for (int j = 0; j < s.n; ++j) p.g[j] = 4.0 * N(rng);
  Eigen::VectorXd xf(s.n);
  for (int j = 0; j < s.n; ++j) xf[j] = N(rng);
  for (int i = 0; i < s.neq; ++i) {
    for (int j = 0; j < s.n; ++j) p.Aeq(i, j) = N(rng);
    p.beq[i] = feasible ? p.Aeq.row(i).dot(xf) : N(rng);
  }
  for (int i = 0; i < s.nin; ++i) {
    for (int j = 0; j < s.n; ++j) p.Ain(i, j) = N(rng);
    const double v = feasible ? p.Ain.row(i).dot(xf) : N(rng);
    const double r = U(rng);
    p.lbA[i] = r < 0.3 ? -kInf : v - (feasible ? U(rng) : N(rng));
    p.ubA[i] = r > 0.7 ? kInf : v + (feasible ? U(rng) : N(rng));
    if (p.lbA[i] > p.ubA[i]) std::swap(p.lbA[i], p.ubA[i]);
    if (U(rng) < 0.1) p.lbA[i] = p.ubA[i] = (feasible ? v : p.ubA[i]);  // equality via a row
    if (p.lbA[i] == kInf || p.ubA[i] == -kInf) p.lbA[i] = -kInf, p.ubA[i] = kInf;
  }
  if (s.bounds)
    for (int j = 0; j < s.n; ++j) {
      const double r = U(rng);
      const double c = feasible ? xf[j] : 0.5 * N(rng);
      if (r < 0.6) p.lb[j] = c - U(rng);
      if (r > 0.3) p.ub[j] = c + U(rng);
      if (U(rng) < 0.1) p.lb[j] = p.ub[j] = c;  // fixed variable
      if (p.lb[j] > p.ub[j]) std::swap(p.lb[j], p.ub[j]);
    }
  return p;
}

// A solve of `p` against the reference: infeasible where the reference is, else optimal, within 1e-7 of the
// reference's x and with KKT residuals under 1e-8.
void expectReferenceResult(const QpProblem& p, const mft::qp::testing::ReferenceResult& ref, QpStatus st,
                           const QpSolution& sol) {
  if (!ref.feasible) {
    EXPECT_EQ(st, QpStatus::Infeasible);
    return;
  }
  ASSERT_EQ(st, QpStatus::Optimal);
  EXPECT_LE((sol.x - ref.x).cwiseAbs().maxCoeff(), 1e-7 * (1.0 + ref.x.cwiseAbs().maxCoeff()));
  EXPECT_LE(kktResiduals(p, sol).max(), 1e-8);
}

// Solves cold and warm (after a solve of `previous`) and checks both against the reference.
void checkAgainstReference(const QpProblem& p, const QpProblem* previous, const std::string& what) {
  SCOPED_TRACE(what);
  const auto ref = referenceSolve(p);
  GoldfarbIdnaniSolver cold;
  QpSolution sol;
  const QpStatus st = cold.solve(p, &sol);
  ASSERT_NO_FATAL_FAILURE(expectReferenceResult(p, ref, st, sol));
  if (!previous) return;
  GoldfarbIdnaniSolver warm;
  warm.options().warm_start = true;
  QpSolution prev_sol;
  warm.solve(*previous, &prev_sol);
  const QpStatus wst = warm.solve(p, &sol);
  EXPECT_EQ(wst, st);
  if (ref.feasible && wst == QpStatus::Optimal) {
    EXPECT_LE((sol.x - ref.x).cwiseAbs().maxCoeff(), 1e-7 * (1.0 + ref.x.cwiseAbs().maxCoeff()));
  }
}

}  // namespace

TEST(QpRandom, FeasibleProblemsMatchEnumeration) {
  std::mt19937 rng(1);
  const Shape shapes[] = {{2, 0, 2, true}, {3, 1, 2, true}, {4, 1, 3, true}, {4, 2, 2, true}, {5, 1, 2, true}};
  for (int trial = 0; trial < 300; ++trial) {
    const Shape& s = shapes[trial % 5];
    const QpProblem p = randomProblem(s, true, rng);
    // Warm start from a perturbation of the same problem (as in a control loop).
    QpProblem prev = p;
    prev.g += Eigen::VectorXd::Constant(s.n, 0.3);
    checkAgainstReference(p, &prev, "trial " + std::to_string(trial));
  }
}

TEST(QpRandom, ArbitraryProblemsAgreeOnFeasibility) {
  std::mt19937 rng(2);
  int infeasible = 0;
  const Shape shapes[] = {{2, 1, 3, true}, {3, 1, 3, true}, {4, 2, 3, true}, {3, 0, 4, true}};
  for (int trial = 0; trial < 300; ++trial) {
    const QpProblem p = randomProblem(shapes[trial % 4], false, rng);
    infeasible += referenceSolve(p).feasible ? 0 : 1;
    checkAgainstReference(p, nullptr, "trial " + std::to_string(trial));
  }
  EXPECT_GT(infeasible, 20);  // the set really exercises both outcomes
}

TEST(QpRandom, BoundsOnlyAndEqualityOnly) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    checkAgainstReference(randomProblem({4, 0, 0, true}, true, rng), nullptr, "bounds only");
    checkAgainstReference(randomProblem({4, 3, 0, false}, true, rng), nullptr, "equality only");
  }
  // Equality only: the solution is the KKT solve itself.
  QpProblem p = randomProblem({5, 2, 0, false}, true, rng);
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  ASSERT_EQ(s.solve(p, &sol), QpStatus::Optimal);
  EXPECT_EQ(sol.iterations, 0);
  EXPECT_LE((p.Aeq * sol.x - p.beq).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(QpRandom, DegenerateRedundantAndDuplicatedRows) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 100; ++trial) {
    QpProblem p = randomProblem({4, 1, 3, true}, true, rng);
    // Row 1 duplicates row 0 scaled, row 2 is the sum of rows 0 and 1 with the matching bound: all can bind together.
    p.Ain.row(1) = 2.0 * p.Ain.row(0);
    p.lbA[1] = 2.0 * p.lbA[0];
    p.ubA[1] = 2.0 * p.ubA[0];
    if (p.lbA[1] > p.ubA[1]) std::swap(p.lbA[1], p.ubA[1]);
    p.Ain.row(2) = p.Ain.row(0) + p.Ain.row(1);
    p.lbA[2] = 3.0 * p.lbA[0];
    p.ubA[2] = 3.0 * p.ubA[0];
    if (p.lbA[2] > p.ubA[2]) std::swap(p.lbA[2], p.ubA[2]);
    p.g *= 3.0;  // push the optimum onto the redundant rows
    checkAgainstReference(p, nullptr, "trial " + std::to_string(trial));
  }
}

TEST(QpRandom, FixedVariableWithAFrictionPyramidThroughIt) {
  // The swing-phase pattern: f_z fixed at 0, rows +-f_x - mu f_z <= 0, cost pulling f_x away from 0.
  // Both pyramid rows and the fixed variable are tight at f = 0 with dependent normals.
  for (double gx : {-5.0, 5.0, 0.0}) {
    QpProblem p;
    p.resize(3, 0, 2);
    p.H = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
    p.dense_block = 1;
    p.g << gx, -3.0, 1.0;
    p.Ain << 1.0, -0.6, 0.0, -1.0, -0.6, 0.0;
    p.ubA << 0.0, 0.0;
    p.lb[1] = p.ub[1] = 0.0;
    GoldfarbIdnaniSolver s;
    QpSolution sol;
    ASSERT_EQ(s.solve(p, &sol), QpStatus::Optimal);
    EXPECT_NEAR(sol.x[0], 0.0, 1e-12);
    EXPECT_EQ(sol.x[1], 0.0);
    EXPECT_NEAR(sol.x[2], -1.0 / 3.0, 1e-12);
    EXPECT_EQ(sol.active[1], 1);  // fixed variables report +1, like active_ref
    EXPECT_LE(kktResiduals(p, sol).max(), 1e-10);
    // Same with the fixed variable inside an equality row too, and stance (f_z >= 0 free to move).
    checkAgainstReference(p, nullptr, "swing");
    p.lb[1] = 0.0;
    p.ub[1] = 1000.0;
    checkAgainstReference(p, nullptr, "stance");
  }
}

TEST(QpRandom, DependentEqualities) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    QpProblem p = randomProblem({4, 3, 2, true}, true, rng);
    p.lb.setConstant(-kInf);  // keep fixed variables out of the picture
    p.ub.setConstant(kInf);
    // Consistent: row 2 = row 0 - 2 row 1 with the matching right-hand side: same solution as without it.
    p.Aeq.row(2) = p.Aeq.row(0) - 2.0 * p.Aeq.row(1);
    p.beq[2] = p.beq[0] - 2.0 * p.beq[1];
    QpProblem reduced = p;
    reduced.neq = 2;
    reduced.Aeq = p.Aeq.topRows(2).eval();
    reduced.beq = p.beq.head(2).eval();
    const auto ref = referenceSolve(reduced);
    GoldfarbIdnaniSolver s;
    QpSolution sol;
    ASSERT_NO_FATAL_FAILURE(expectReferenceResult(p, ref, s.solve(p, &sol), sol));
    if (!ref.feasible) continue;
    // Inconsistent: the same dependent row with another right-hand side.
    p.beq[2] += 1.0;
    EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  }
}

TEST(QpRandom, ContradictoryConstraintsAreInfeasible) {
  QpProblem p;
  p.resize(3, 1, 2);
  p.H.setIdentity();
  p.g << 1.0, 2.0, 3.0;
  p.Aeq << 0.0, 0.0, 1.0;
  p.beq << 1.0;
  // Rows: x0 + x1 >= 2 and 2 x0 + 2 x1 <= 1.
  p.Ain << 1.0, 1.0, 0.0, 2.0, 2.0, 0.0;
  p.lbA << 2.0, -kInf;
  p.ubA << kInf, 1.0;
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  EXPECT_EQ(sol.status, QpStatus::Infeasible);
  // Bounds against rows: x0, x1 <= 0.5 and x0 + x1 >= 2.
  p.ubA[1] = kInf;
  p.ub << 0.5, 0.5, kInf;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  // Equality against a bound, and crossed bounds / row sides.
  p.ub << kInf, kInf, 0.0;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  p.ub.setConstant(kInf);
  p.lb[0] = 1.0;
  p.ub[0] = 0.0;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  p.lb[0] = -kInf;
  p.ub[0] = kInf;
  p.lbA[0] = 3.0;
  p.ubA[0] = 2.0;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Infeasible);
  p.lbA[0] = 2.0;
  p.ubA[0] = kInf;
  EXPECT_EQ(s.solve(p, &sol), QpStatus::Optimal);  // and it recovers
}

TEST(QpRandom, LargerStructuredProblemsSatisfyKkt) {
  // WBC-sized problems (27 variables, dense 11 block, 7 equalities, 20 rows, boxes): no enumeration possible,
  // but KKT at tolerance certifies optimality of a convex QP.
  std::mt19937 rng(6);
  std::normal_distribution<double> N(0.0, 1.0);
  GoldfarbIdnaniSolver warm(27, 7, 20);
  warm.options().warm_start = true;
  QpSolution sol, sol_cold;
  for (int trial = 0; trial < 200; ++trial) {
    QpProblem p = randomProblem({27, 7, 20, true}, true, rng);
    p.H = randomBlockH(27, 11, rng);
    p.dense_block = 11;
    for (int j = 0; j < 27; ++j) p.g[j] = 30.0 * N(rng);
    GoldfarbIdnaniSolver cold;
    ASSERT_EQ(cold.solve(p, &sol_cold), QpStatus::Optimal) << trial;
    EXPECT_LE(kktResiduals(p, sol_cold).max(), 1e-8) << trial;
    ASSERT_EQ(warm.solve(p, &sol), QpStatus::Optimal) << trial;
    EXPECT_LE((sol.x - sol_cold.x).cwiseAbs().maxCoeff(), 1e-8) << trial;
  }
}
