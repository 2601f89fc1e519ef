// The solver on the 200 shared WBC instances (shared/qp/instances/seq_1600_1799): matches the qpOASES
// reference x_ref to 1e-6 and satisfies KKT to 1e-8, cold and warm-started in sequence.
#include <gtest/gtest.h>

#include <cmath>

#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_kkt.hpp"
#include "wbc/qp/qp_solver.hpp"

using namespace mft::qp;

namespace {

const std::vector<QpInstance>& sharedInstances() {
  static const std::vector<QpInstance> instances = [] {
    std::vector<QpInstance> v;
    for (const std::string& f : listQpInstanceFiles(std::string(MFT_SHARED_DIR) + "/qp/instances/seq_1600_1799"))
      v.push_back(readQpInstance(f));
    return v;
  }();
  return instances;
}

void solveSequence(bool warm) {
  const auto& instances = sharedInstances();
  ASSERT_EQ(instances.size(), 200u);
  const QpProblem& first = instances.front().problem;
  GoldfarbIdnaniSolver solver(first.n, first.neq, first.nin);
  solver.options().warm_start = warm;
  QpSolution sol;
  int warm_solves = 0;
  for (const QpInstance& inst : instances) {
    SCOPED_TRACE(inst.name);
    ASSERT_TRUE(inst.x_ref && inst.f_ref && inst.active_ref);
    ASSERT_EQ(solver.solve(inst.problem, &sol), QpStatus::Optimal);
    EXPECT_EQ(sol.status, QpStatus::Optimal);
    EXPECT_FALSE(solver.lastSolveFellBack());
    warm_solves += solver.lastSolveWasWarm() ? 1 : 0;
    EXPECT_LE((sol.x - *inst.x_ref).cwiseAbs().maxCoeff(), 1e-6);
    const KktResiduals r = kktResiduals(inst.problem, sol);
    EXPECT_LE(r.max(), 1e-8) << "stationarity " << r.stationarity << " primal " << r.primal << " dual " << r.dual
                             << " complementarity " << r.complementarity;
    EXPECT_NEAR(sol.objective, *inst.f_ref, 1e-9 * (1.0 + std::abs(*inst.f_ref)));
    EXPECT_LE(sol.iterations, 11);
  }
  if (warm) {
    EXPECT_GE(warm_solves, 150);  // steps after one with no active inequality start cold
  }
}

}  // namespace

TEST(QpSharedInstances, ColdMatchesReferenceAndKkt) { solveSequence(false); }

TEST(QpSharedInstances, WarmSequenceMatchesReferenceAndKkt) { solveSequence(true); }

TEST(QpSharedInstances, ActiveSetMatchesReferenceExceptDegenerateTies) {
  // Differences are allowed only where every side either set claims is tight at the solution.
  GoldfarbIdnaniSolver solver;
  QpSolution sol;
  int differing_steps = 0;
  for (const QpInstance& inst : sharedInstances()) {
    const QpProblem& p = inst.problem;
    ASSERT_EQ(solver.solve(p, &sol), QpStatus::Optimal);
    const Eigen::VectorXd rows = p.Ain * sol.x;
    bool differs = false;
    for (int i = 0; i < p.n + p.nin; ++i) {
      const int ours = sol.active[i], ref = (*inst.active_ref)[i];
      if (ours == ref) continue;
      differs = true;
      const bool bound = i < p.n;
      const int k = bound ? i : i - p.n;
      const double v = bound ? sol.x[k] : rows[k];
      const double lo = bound ? p.lb[k] : p.lbA[k], hi = bound ? p.ub[k] : p.ubA[k];
      for (int side : {ours, ref})
        if (side) {
          EXPECT_LE(side < 0 ? std::abs(v - lo) : std::abs(hi - v), 1e-7) << inst.name << " entry " << i;
        }
    }
    differing_steps += differs ? 1 : 0;
  }
  EXPECT_LE(differing_steps, 10);  // ties at the friction-cone apex (f = 0 with f_z >= 0 and both rows tight)
}
