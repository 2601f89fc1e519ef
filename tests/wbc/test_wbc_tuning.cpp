// Live tuning, WBC side (docs/guide/live-tuning.md): a change is judged by config/wbc.yaml's strict loader (its
// messages for an unknown key or an invalid value, a refusal for a key that is not tunable), and
// WholeBodyController::setTuning makes a running controller compute what a controller built with the changed
// file computes.
#include <gtest/gtest.h>

#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"
#include "wbc/whole_body_controller.hpp"
#include "wbc/wbc_tuning.hpp"
#include "wbc_test_support.hpp"

using namespace mft;
using namespace mft::wbc;

namespace {

std::string projectText() { return mft::test::readTextFile(std::string(MFT_CONFIG_DIR) + "/wbc.yaml"); }

std::string refusal(const std::string& key, const std::string& value) {
  return mft::test::refusalOf(
      [&] { applyWbcOverride(projectText(), "wbc.yaml (live change)", key, value, wbc::test::robot()); });
}

}  // namespace

TEST(WbcTuning, AChangeIsReadByTheStrictLoaderAndTouchesOnlyItsKey) {
  const WbcConfig before = wbc::test::projectConfig(WbcVariant::Mft);
  const WbcOverride o = applyWbcOverride(projectText(), "wbc.yaml (live change)", "weights.slack", "1e5", wbc::test::robot());
  EXPECT_EQ(o.config.weights.slack, 1e5);
  EXPECT_EQ(o.value, std::vector<double>{1e5});
  EXPECT_EQ(o.previous, std::vector<double>{before.weights.slack});
  EXPECT_EQ(o.config.weights.base_z, before.weights.base_z);
  EXPECT_EQ(o.config.gains.base_z.kp, before.gains.base_z.kp);
  // A change on top of the previous one (the service judges each against the text in force).
  const WbcOverride o2 = applyWbcOverride(o.yaml_text, "wbc.yaml (live change)", "gains.swing_foot.kp", "[300, 250]",
                                          wbc::test::robot());
  EXPECT_EQ(o2.config.weights.slack, 1e5);
  EXPECT_EQ(o2.config.gains.swing_foot.kp, Eigen::Vector2d(300, 250));
  EXPECT_EQ(o2.previous, (std::vector<double>{before.gains.swing_foot.kp[0], before.gains.swing_foot.kp[1]}));
}

TEST(WbcTuning, RefusalsCarryTheLoadersMessage) {
  EXPECT_EQ(refusal("weights.slack", "abc"), "wbc.yaml (live change): weights.slack: expected a number, got 'abc'");
  EXPECT_EQ(refusal("weights.slak", "1"), "wbc.yaml (live change): unknown key weights.slak");
  EXPECT_EQ(refusal("weights.slack", "-1"), "wbc.yaml (live change): weights.slack: must be > 0 (got -1.000000)");
  EXPECT_EQ(refusal("gains.swing_foot.kp", "[1, 2, 3]").rfind("wbc.yaml (live change): gains.swing_foot.kp: ", 0), 0u);
  // Valid for the loader, but structure: not tunable while the stack runs.
  EXPECT_EQ(refusal("variant", "sa"),
            "wbc.yaml (live change): variant: not tunable while the stack runs (tunable: weights.*, gains.*)");
  EXPECT_NE(refusal("limits.qdd_joint_max_radps2", "100").find("not tunable"), std::string::npos);
  EXPECT_NE(refusal("weights.slack.x", "1").find("weights.slack: is a value, not a section"), std::string::npos);
}

TEST(WbcTuning, EveryTunableKeyExistsInTheFileAndIsAccepted) {
  const std::string text = projectText();
  int n = 0;
  for (const auto& k : config::tunableKeys()) {
    if (std::string(k.stem) != "wbc") continue;
    const auto now = config::numbersAt(text, k.key);
    ASSERT_EQ(static_cast<int>(now.size()), k.size) << k.key;
    EXPECT_EQ(refusal(k.key, config::formatNumbers(now.data(), now.size())), "accepted") << k.key;
    ++n;
  }
  EXPECT_EQ(n, 19);
}

TEST(WbcTuning, SetTuningActsLikeAControllerBuiltWithTheChangedFile) {
  const WbcPolytope poly = wbc::test::testPolytope();
  wbc::test::StateSpec s;
  s.base_vel = {0.05, -0.1, 0.2};  // the PD terms see an error
  const model::RobotStateEstimate st = wbc::test::makeState(s);
  WbcReference ref = wbc::test::holdReference(st);
  ref.base_z.pos += 0.01;
  const WbcOverride o = applyWbcOverride(projectText(), "wbc.yaml (live change)", "gains.base_z.kp", "100", wbc::test::robot());
  WbcOverride o2 = applyWbcOverride(o.yaml_text, "wbc.yaml (live change)", "weights.contact_force", "1e-2", wbc::test::robot());
  o2.config.variant = WbcVariant::Mft;

  WholeBodyController tuned(wbc::test::robot(), wbc::test::projectConfig(WbcVariant::Mft), poly);
  WholeBodyController fresh(wbc::test::robot(), o2.config, poly);
  WholeBodyController untouched(wbc::test::robot(), wbc::test::projectConfig(WbcVariant::Mft), poly);
  tuned.setTuning(tuningOf(o2.config));
  EXPECT_EQ(tuned.tuning().gains.base_z.kp, 100.0);
  EXPECT_EQ(tuned.tuning().weights.contact_force, 1e-2);
  WbcDiagnostics d1, d2, d3;
  const auto a = tuned.update(st, ref, &d1);
  const auto b = fresh.update(st, ref, &d2);
  const auto c = untouched.update(st, ref, &d3);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.tau[i], b.tau[i]) << i;
  EXPECT_GT((a.tau - c.tau).cwiseAbs().maxCoeff(), 0.1) << "the change made no difference";
}
