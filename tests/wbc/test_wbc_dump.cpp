// The QP of a tick dumped in the shared WBCQP v1 format reads back identically and solves to the same x.
#include <unistd.h>
#include <gtest/gtest.h>

#include <cstdio>

#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_solver.hpp"
#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

TEST(WbcQpDump, RoundTripThroughTheSharedFormat) {
  const WbcPolytope poly = test::testPolytope();
  WholeBodyController wbc(test::robot(), test::projectConfig(WbcVariant::Mft), poly);
  EXPECT_THROW(wbc.writeLastQp(::testing::TempDir() + "/none.txt"), std::runtime_error);
  test::StateSpec s;
  s.left_foot = {-0.02, -0.445};  // MFT rows active
  const model::RobotStateEstimate st = test::makeState(s, 1234);
  WbcDiagnostics diag;
  wbc.update(st, test::holdReference(st, true, true), &diag);
  ASSERT_EQ(diag.status, qp::QpStatus::Optimal);
  const std::string path = ::testing::TempDir() + "/wbc_01234_" + std::to_string(getpid()) + ".txt";
  wbc.writeLastQp(path);

  const qp::QpInstance inst = qp::readQpInstance(path);
  EXPECT_EQ(inst.name, "wbc_01234");
  ASSERT_TRUE(inst.step.has_value());
  EXPECT_EQ(*inst.step, 1234);
  const qp::QpProblem& a = wbc.lastProblem();
  const qp::QpProblem& b = inst.problem;
  ASSERT_EQ(b.n, a.n);
  ASSERT_EQ(b.neq, a.neq);
  ASSERT_EQ(b.nin, a.nin);
  EXPECT_EQ(b.H, a.H);  // %.17g: bit-exact
  EXPECT_EQ(b.g, a.g);
  EXPECT_EQ(b.Aeq, a.Aeq);
  EXPECT_EQ(b.Ain, a.Ain);
  EXPECT_EQ(b.ubA, a.ubA);
  EXPECT_EQ(b.lb, a.lb);
  ASSERT_EQ(inst.varblocks.size(), 3u);
  EXPECT_EQ(inst.varblocks[1].name, "f_c");
  EXPECT_EQ(inst.varblocks[2].first, 15);
  ASSERT_EQ(inst.rowblocks.size(), 5u);
  EXPECT_EQ(inst.rowblocks[0].name, "eq_base_dyn");
  EXPECT_EQ(inst.rowblocks[4].name, "in_mft");
  EXPECT_EQ(inst.rowblocks[4].first, 8);
  ASSERT_TRUE(inst.x_ref.has_value());
  EXPECT_EQ(*inst.x_ref, wbc.lastSolution().x);

  qp::GoldfarbIdnaniSolver solver(b.n, b.neq, b.nin);
  qp::QpSolution sol;
  ASSERT_EQ(solver.solve(b, &sol), qp::QpStatus::Optimal);
  EXPECT_LT((sol.x - *inst.x_ref).cwiseAbs().maxCoeff(), 1e-9);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace mft::wbc
