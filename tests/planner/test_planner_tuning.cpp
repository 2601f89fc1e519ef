// Live tuning, planner side (docs/guide/live-tuning.md): a change of config/planner.yaml is judged by its strict loader,
// gait timing is refused as structure, and every tunable planner key exists in the file.
#include <gtest/gtest.h>

#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"
#include "planner/planner_tuning.hpp"

using namespace mft;
using namespace mft::planner;

namespace {
std::string projectText() { return mft::test::readTextFile(std::string(MFT_CONFIG_DIR) + "/planner.yaml"); }
std::string refusal(const std::string& key, const std::string& value) {
  return mft::test::refusalOf([&] { applyPlannerOverride(projectText(), "planner.yaml (live change)", key, value); });
}
}  // namespace

TEST(PlannerTuning, AChangeIsReadByTheStrictLoader) {
  const auto o = applyPlannerOverride(projectText(), "planner.yaml (live change)", "foot_placement.k_v", "0.145");
  EXPECT_EQ(o.config.placement.k_v, 0.145);
  EXPECT_EQ(o.previous, std::vector<double>{0.16});
  EXPECT_EQ(tuningOf(o.config).placement.k_v, 0.145);
  EXPECT_EQ(tuningOf(o.config).swing.lift_height_m, 0.06);
  EXPECT_EQ(refusal("swing.replan_until_phase", "1.5"),
            "planner.yaml (live change): swing.replan_until_phase: must lie in [0, 1] (got 1.5)");
  EXPECT_EQ(refusal("gait.step_duration_s", "0.3"),
            "planner.yaml (live change): gait.step_duration_s: not tunable while the stack runs (tunable: swing.*, "
            "foot_placement.*, command.height_rate_mps)");
}

TEST(PlannerTuning, EveryTunableKeyExistsInTheFileAndIsAccepted) {
  int n = 0;
  for (const auto& k : config::tunableKeys()) {
    if (std::string(k.stem) != "planner") continue;
    const auto now = config::numbersAt(projectText(), k.key);
    ASSERT_EQ(static_cast<int>(now.size()), k.size) << k.key;
    EXPECT_EQ(refusal(k.key, config::formatNumbers(now.data(), now.size())), "accepted") << k.key;
    ++n;
  }
  EXPECT_EQ(n, 8);
}
