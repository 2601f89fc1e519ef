// config/planner.yaml: the shipped file loads with the paper's values; bad files fail naming file and key.
#include <gtest/gtest.h>

#include "common/strict_yaml.hpp"
#include "planner/planner_config.hpp"
#include "tests/support/config_test_support.hpp"

using namespace mft::planner;

namespace {
std::string path() { return std::string(MFT_CONFIG_DIR) + "/planner.yaml"; }
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  mft::test::expectConfigError(mft::test::readTextFile(path()), pattern, replacement, "bad-planner.yaml", expect,
                               parsePlannerConfig);
}
}  // namespace

TEST(PlannerConfig, DefaultFileHasThePaperValues) {
  const auto c = loadPlannerConfig(path());
  EXPECT_DOUBLE_EQ(c.gait.step_duration_s, 0.35);
  EXPECT_DOUBLE_EQ(c.placement.k_v, 0.16);  // the paper's (section IV-A); 0.145 is the profile kv-0.145
  EXPECT_DOUBLE_EQ(c.placement.k_p, 0.08);
  EXPECT_EQ(c.command.initial_mode, LocomotionMode::Stand);
  EXPECT_EQ(c.source_file, path());
}

TEST(PlannerConfig, MissingKeyIsNamed) { expectError(R"(\n  k_p: 0.08[^\n]*)", "", "foot_placement.k_p: missing key"); }
TEST(PlannerConfig, UnknownKeyIsNamed) { expectError(R"(  k_v: [0-9.]+)", "$&\n  k_i: 0.01", "unknown key foot_placement.k_i"); }
TEST(PlannerConfig, WrongTypeIsNamed) { expectError(R"(step_duration_s: 0.35)", "step_duration_s: slow", "gait.step_duration_s: expected a number"); }
TEST(PlannerConfig, NonPositiveDurationIsRefused) { expectError(R"(step_duration_s: 0.35)", "step_duration_s: 0", "gait.step_duration_s: must be > 0"); }
TEST(PlannerConfig, PhaseOutOfRangeIsRefused) { expectError(R"(min_touchdown_phase: 0.6)", "min_touchdown_phase: 1.5", "gait.min_touchdown_phase: must lie in"); }
TEST(PlannerConfig, BadLegIsNamed) { expectError(R"(first_swing_leg: right)", "first_swing_leg: middle", "gait.first_swing_leg: expected right or left"); }
TEST(PlannerConfig, BadModeIsNamed) { expectError(R"(mode: stand)", "mode: run", "command.initial.mode: expected stand"); }
TEST(PlannerConfig, InvertedWindowIsRefused) { expectError(R"(height_window_m: \[0.30, 0.46\])", "height_window_m: [0.46, 0.30]", "command.height_window_m"); }
TEST(PlannerConfig, MissingFileIsAClearError) {
  try {
    loadPlannerConfig("/nonexistent/planner.yaml");
    FAIL();
  } catch (const mft::config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/planner.yaml: cannot open the file"), std::string::npos) << e.what();
  }
}
