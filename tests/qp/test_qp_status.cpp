// Statuses other than Optimal, the unconstrained start's sign, the block-structure hint, and no allocation in
// solve() once sized.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "qp_instance_set.hpp"
#include "qp_reference.hpp"
#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_kkt.hpp"
#include "wbc/qp/qp_solver.hpp"

using namespace mft::qp;

// Counts heap allocations while enabled (whole test binary; only the allocation test enables it).
namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  if (g_count_allocations) ++g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
// GCC 12 flags free() in a replaced operator delete as a new/free mismatch; here both sides are ours.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace {

using mft::qp::testing::instanceSet;

// MFT-WBC instances of the set (27 variables, 7 equalities, 20 rows), in file order.
std::vector<QpInstance> mftInstances() {
  std::vector<QpInstance> v;
  for (const QpInstance& inst : instanceSet())
    if (inst.problem.n == 27 && inst.problem.neq == 7 && inst.problem.nin == 20) v.push_back(inst);
  return v;
}

// The MFT-WBC instance whose cold solve needs the most working-set changes (the first of equals).
QpInstance hardestInstance() {
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  QpInstance best;
  int most = -1;
  for (const QpInstance& inst : mftInstances())
    if (s.solve(inst.problem, &sol) == QpStatus::Optimal && sol.iterations > most) most = sol.iterations, best = inst;
  return best;
}

QpProblem unconstrained(int n, int block, unsigned seed) {
  std::mt19937 rng(seed);
  QpProblem p;
  p.resize(n, 0, 0);
  p.H = mft::qp::testing::randomBlockH(n, block, rng);
  p.dense_block = block;
  std::normal_distribution<double> N(0.0, 1.0);
  for (int j = 0; j < n; ++j) p.g[j] = N(rng);
  return p;
}

}  // namespace

TEST(QpStatus, UnconstrainedStartIsMinusHInverseG) {
  // docs/reference/qp.md#unconstrained-start: eiquadprog's provided-factor path returns +J J' g. Ours must give -H^-1 g, dense or block-structured.
  for (int block : {6, 3, 1}) {
    QpProblem p = unconstrained(6, block, 10 + block);
    const Eigen::VectorXd expected = -p.H.llt().solve(p.g);
    for (int hint : {0, block}) {
      p.dense_block = hint;
      GoldfarbIdnaniSolver s;
      QpSolution sol;
      ASSERT_EQ(s.solve(p, &sol), QpStatus::Optimal);
      EXPECT_LE((sol.x - expected).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_NEAR(sol.objective, 0.5 * p.g.dot(expected), 1e-12);
      EXPECT_EQ(sol.iterations, 0);
    }
  }
}

TEST(QpStatus, WrongBlockHintFallsBackToDense) {
  QpProblem p = unconstrained(5, 5, 3);  // dense H, but the hint claims only 2x2 is dense
  p.dense_block = 2;
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  ASSERT_EQ(s.solve(p, &sol), QpStatus::Optimal);
  EXPECT_LE((sol.x + p.H.llt().solve(p.g)).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(QpStatus, NonFiniteDataIsANumericalFailure) {
  ASSERT_FALSE(mftInstances().empty());
  const QpInstance inst = mftInstances().front();
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto expectFailure = [&](auto mutate, const char* what) {
    QpProblem p = inst.problem;
    mutate(p);
    EXPECT_EQ(s.solve(p, &sol), QpStatus::NumericalFailure) << what;
    EXPECT_EQ(sol.status, QpStatus::NumericalFailure) << what;
    EXPECT_TRUE(sol.x.hasNaN()) << what;  // never a plausible-looking x
  };
  expectFailure([&](QpProblem& p) { p.g[3] = nan; }, "g NaN");
  expectFailure([&](QpProblem& p) { p.H(2, 2) = kInf; }, "H inf");
  expectFailure([&](QpProblem& p) { p.H(20, 20) = nan; }, "H diagonal part NaN");
  expectFailure([&](QpProblem& p) { p.Aeq(1, 1) = -kInf; }, "Aeq inf");
  expectFailure([&](QpProblem& p) { p.beq[0] = nan; }, "beq NaN");
  expectFailure([&](QpProblem& p) { p.Ain(5, 4) = nan; }, "Ain NaN");
  expectFailure([&](QpProblem& p) { p.lb[0] = nan; }, "lb NaN");
  expectFailure([&](QpProblem& p) { p.ubA[7] = nan; }, "ubA NaN");
  expectFailure([&](QpProblem& p) { p.g.resize(5); }, "wrong size");
  // Infinite bounds are legal; the instance still solves after all that.
  EXPECT_EQ(s.solve(inst.problem, &sol), QpStatus::Optimal);
}

TEST(QpStatus, NonPositiveDefiniteHIsANumericalFailure) {
  QpProblem p = unconstrained(4, 4, 7);
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  p.H(0, 0) = -1.0;  // indefinite
  EXPECT_EQ(s.solve(p, &sol), QpStatus::NumericalFailure);
  p = unconstrained(4, 2, 8);
  p.H(3, 3) = 0.0;  // singular in the diagonal block
  EXPECT_EQ(s.solve(p, &sol), QpStatus::NumericalFailure);
  p = unconstrained(3, 3, 9);
  p.H.setOnes();  // rank one
  EXPECT_EQ(s.solve(p, &sol), QpStatus::NumericalFailure);
}

TEST(QpStatus, IterationCapYieldsIterationLimit) {
  const QpInstance inst = hardestInstance();
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  ASSERT_EQ(s.solve(inst.problem, &sol), QpStatus::Optimal);
  const int needed = sol.iterations;
  ASSERT_GE(needed, 2);
  s.options().max_iterations = needed - 1;
  EXPECT_EQ(s.solve(inst.problem, &sol), QpStatus::IterationLimit);
  EXPECT_EQ(sol.status, QpStatus::IterationLimit);
  s.options().max_iterations = 0;
  EXPECT_EQ(s.solve(inst.problem, &sol), QpStatus::IterationLimit);
  // Warm start that hits the cap falls back to cold, which hits it too.
  GoldfarbIdnaniSolver w;
  w.options().warm_start = true;
  ASSERT_EQ(w.solve(mftInstances().back().problem, &sol), QpStatus::Optimal);
  w.options().max_iterations = 0;
  EXPECT_EQ(w.solve(inst.problem, &sol), QpStatus::IterationLimit);
  w.options().max_iterations = 200;
  EXPECT_EQ(w.solve(inst.problem, &sol), QpStatus::Optimal);
}

TEST(QpStatus, SolveAllocatesNothingOnceSized) {
  // Every MFT-WBC instance of the set: same sizes, many different active sets.
  const std::vector<QpInstance> seq = mftInstances();
  ASSERT_GE(seq.size(), 20u);
  for (bool warm : {false, true}) {
    GoldfarbIdnaniSolver s(27, 7, 20);
    s.options().warm_start = warm;
    QpSolution sol;
    sol.resize(27, 7, 20);
    g_allocations = 0;
    g_count_allocations = true;
    for (int rep = 0; rep < 3; ++rep)
      for (const QpInstance& inst : seq) EXPECT_EQ(s.solve(inst.problem, &sol), QpStatus::Optimal);
    QpProblem bad = seq[0].problem;
    bad.g[0] = std::numeric_limits<double>::quiet_NaN();
    s.solve(bad, &sol);
    g_count_allocations = false;
    EXPECT_EQ(g_allocations.load(), 0) << (warm ? "warm" : "cold");
  }
}

TEST(QpStatus, SolutionConventions) {
  const QpInstance inst = hardestInstance();
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  ASSERT_EQ(s.solve(inst.problem, &sol), QpStatus::Optimal);
  const QpProblem& p = inst.problem;
  ASSERT_EQ(sol.active.size(), p.n + p.nin);
  // Multiplier signs follow the side: lower -> y >= 0, upper -> y <= 0, inactive -> 0.
  for (int i = 0; i < p.n + p.nin; ++i) {
    const double y = i < p.n ? sol.y_bounds[i] : sol.y_rows[i - p.n];
    const bool fixed = i < p.n && p.lb[i] == p.ub[i];
    if (fixed) continue;
    if (sol.active[i] == 0) {
      EXPECT_EQ(y, 0.0) << i;
    }
    if (sol.active[i] < 0) {
      EXPECT_GE(y, 0.0) << i;
    }
    if (sol.active[i] > 0) {
      EXPECT_LE(y, 0.0) << i;
    }
  }
  const Eigen::VectorXd grad = p.H * sol.x + p.g - p.Aeq.transpose() * sol.y_eq - sol.y_bounds - p.Ain.transpose() * sol.y_rows;
  EXPECT_LE(grad.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(sol.objective, 0.5 * sol.x.dot(p.H * sol.x) + p.g.dot(sol.x), 1e-9);
}

TEST(QpStatus, KktCheckerDetectsEachViolation) {
  const QpInstance inst = hardestInstance();
  GoldfarbIdnaniSolver s;
  QpSolution sol;
  ASSERT_EQ(s.solve(inst.problem, &sol), QpStatus::Optimal);
  EXPECT_LE(kktResiduals(inst.problem, sol).max(), 1e-9);
  QpSolution bad = sol;
  bad.x[0] += 1e-3;
  EXPECT_GT(kktResiduals(inst.problem, bad).stationarity, 1e-5);
  bad = sol;
  bad.x[16] = 1e3;  // eps, also breaks stationarity; and qdd beyond its box:
  bad.x[3] = inst.problem.ub[3] + 80.0;
  EXPECT_GE(kktResiduals(inst.problem, bad).primal, 79.9);
  bad = sol;
  bad.y_bounds[20] = 1.0;  // eps has no bounds: any multiplier is dual-infeasible
  EXPECT_GE(kktResiduals(inst.problem, bad).dual, 1.0);
  bad = sol;
  ASSERT_GT(sol.x[0] - inst.problem.lb[0], 1.0);
  bad.y_bounds[0] = 1.0;  // lower bound of qdd_0 is not tight
  EXPECT_GT(kktResiduals(inst.problem, bad).complementarity, 1.0);
}
