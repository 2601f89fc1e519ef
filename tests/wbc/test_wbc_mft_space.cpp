// The controller with the project's offline polytope (config/mft_space.yaml, tools/mft-space).
#include <gtest/gtest.h>

#include "model/mft_polytope.hpp"
#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

model::MftPolytope projectPolytope() {
  return model::loadMftPolytope(std::string(MFT_CONFIG_DIR) + "/mft_space.yaml", test::robot());
}

TEST(WbcMftSpace, NominalStanceIsInsideAndIndicesAreReported) {
  const model::MftPolytope poly = projectPolytope();
  WholeBodyController wbc(test::robot(), test::projectConfig(WbcVariant::Mft), &poly);
  test::StateSpec s;
  s.right_foot = {0.0, -0.40};
  s.left_foot = {0.0, -0.40};
  const model::RobotStateEstimate st = test::makeState(s);
  WbcDiagnostics d;
  wbc.update(st, test::holdReference(st), &d);
  ASSERT_EQ(d.status, qp::QpStatus::Optimal);
  EXPECT_LT(d.mft_violation, 0.0);
  EXPECT_LT(d.slack_norm, 1e-9);
  // docs/reference/five-bar-theory.md#vertical-stance-numbers, vertical stance at 0.40 m: LTI 0.875, RACI* 158.2 N/sqrt(kg).
  for (int leg = 0; leg < 2; ++leg) {
    EXPECT_NEAR(d.lti[leg], 0.875, 2e-3);
    EXPECT_NEAR(d.raci[leg], 158.2, 1.0);
  }
}

TEST(WbcMftSpace, StretchedStanceLegIsPulledBack) {
  const model::MftPolytope poly = projectPolytope();
  test::StateSpec s;
  s.left_foot = {-0.02, -0.445};
  const model::RobotStateEstimate st = test::makeState(s);
  const WbcReference ref = test::holdReference(st);
  double pred[2];
  int i = 0;
  for (WbcVariant v : {WbcVariant::Mft, WbcVariant::None}) {
    WbcConfig cfg = test::projectConfig(v);
    cfg.weights.contact_force = 1e-9;  // no sag from the force regularization (see test_wbc_variants.cpp)
    WholeBodyController wbc(test::robot(), cfg, &poly);
    WbcDiagnostics d;
    for (int k = 0; k < 300; ++k) wbc.update(st, ref, &d);
    ASSERT_EQ(d.status, qp::QpStatus::Optimal);
    ASSERT_GT(d.mft_violation, 0.02);
    pred[i++] = d.mft_violation_predicted;
    if (v == WbcVariant::None) EXPECT_NEAR(d.mft_violation_predicted, d.mft_violation, 0.01 * d.mft_violation);
    else EXPECT_LT(d.mft_violation_predicted, 0.95 * d.mft_violation);
  }
  EXPECT_LT(pred[0], pred[1]);
}

TEST(WbcMftSpace, PolytopeOfAnotherRobotIsRefused) {
  model::MftPolytope poly = projectPolytope();
  poly.robot_checksum ^= 1;
  EXPECT_THROW(WholeBodyController(test::robot(), test::projectConfig(WbcVariant::Mft), &poly), std::invalid_argument);
}

}  // namespace
}  // namespace mft::wbc
