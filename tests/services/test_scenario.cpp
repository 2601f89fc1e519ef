// Scenario files: the shipped scenarios load; every malformed scenario is refused naming the file and key.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/strict_yaml.hpp"
#include "chain/scenario.hpp"
#include "tests/support/config_test_support.hpp"

using mft::config::ConfigError;
using namespace mft::chain;

namespace {
std::string scenarioDir() { return std::string(MFT_CONFIG_DIR) + "/scenarios"; }
std::string stepText() { return mft::test::readTextFile(scenarioDir() + "/step-in-place.yaml"); }
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  mft::test::expectConfigError(stepText(), pattern, replacement, "bad.yaml", expect, parseScenario);
}
}  // namespace

TEST(Scenario, EveryShippedScenarioLoads) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(scenarioDir())) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Scenario s = loadScenario(entry.path().string());
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_TRUE(std::filesystem::exists(std::string(MFT_CONFIG_DIR) + "/terrain/" + s.terrain + ".yaml"))
        << "terrain " << s.terrain << " has no file";
    ++count;
  }
  EXPECT_GE(count, 1);
}

TEST(Scenario, StepInPlaceHasItsCommands) {
  const Scenario s = parseScenario(stepText(), "step.yaml");
  ASSERT_EQ(s.commands.size(), 2u);
  EXPECT_EQ(s.commands[1].mode, LocomotionMode::StepInPlace);
  EXPECT_DOUBLE_EQ(s.commands[1].z_cmd_m, 0.42);
  EXPECT_EQ(s.controller, "mft");
  EXPECT_NE(s.toJson().find("\"mode\": \"step_in_place\""), std::string::npos);
}

TEST(Scenario, PushesAtTimeAndAtLiftoff) {
  const Scenario s = parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 3.0, at_s: 4.0}\n"
                                                "  - {impulse_Ns: -2.5, at_s: 6.0, at_liftoff: left}\n", "p.yaml");
  ASSERT_EQ(s.pushes.size(), 2u);
  EXPECT_EQ(s.pushes[0].at_liftoff_leg, -1);
  EXPECT_EQ(s.pushes[1].at_liftoff_leg, 1);
  EXPECT_DOUBLE_EQ(s.pushes[1].impulse_Ns, -2.5);
}

TEST(Scenario, PushAtAGaitPhase) {
  const Scenario s = parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 5, at_s: 3, at_phase: 0.25, stance: left}\n",
                                   "g.yaml");
  ASSERT_EQ(s.pushes.size(), 1u);
  EXPECT_DOUBLE_EQ(s.pushes[0].at_phase, 0.25);
  EXPECT_EQ(s.pushes[0].stance_leg, 1);
  EXPECT_EQ(s.pushes[0].at_liftoff_leg, -1);
  EXPECT_NE(s.toJson().find("\"at_phase\": 0.25"), std::string::npos);
  EXPECT_THROW(parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 5, at_s: 3, at_phase: 0.25, stance: left, "
                                          "at_liftoff: right}\n", "g.yaml"), ConfigError);
  EXPECT_THROW(parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 5, at_s: 3, at_phase: 1.5, stance: left}\n",
                             "g.yaml"), ConfigError);
  EXPECT_THROW(parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 5, at_s: 3, at_phase: 0.5}\n", "g.yaml"),
               ConfigError);
}

TEST(Scenario, UnknownTopLevelKey) { expectError("duration_s: 10.0", "duration_s: 10.0\nspeed: 3", "unknown key speed"); }
TEST(Scenario, UnknownKeyInsideAListItem) {
  expectError("    v_cmd_mps: 0.0", "    v_cmd_mps: 0.0\n    colour: red", "commands[0].colour");
}
TEST(Scenario, BadController) { expectError("controller: mft", "controller: pid", "controller: unknown value 'pid'"); }
TEST(Scenario, BadMode) { expectError("mode: stand", "mode: dance", "commands[0].mode: unknown mode 'dance'"); }
TEST(Scenario, MissingKey) { expectError("duration_s: 10.0\n", "", "duration_s: missing key"); }
TEST(Scenario, NegativeCommandTime) { expectError("at_s: 1.0", "at_s: -1.0", "commands[1].at_s: must lie in"); }
TEST(Scenario, CommandsOutOfOrder) {
  EXPECT_THROW(parseScenario(stepText() + "  - {at_s: 0.5, mode: stand, z_cmd_m: 0.4, v_cmd_mps: 0}\n", "o.yaml"), ConfigError);
}
TEST(Scenario, PushWithBadLeg) {
  EXPECT_THROW(parseScenario(stepText() + "pushes:\n  - {impulse_Ns: 3, at_s: 1, at_liftoff: middle}\n", "x.yaml"),
               ConfigError);
}
TEST(Scenario, MalformedYaml) { EXPECT_THROW(parseScenario("name: [unclosed\n", "broken.yaml"), ConfigError); }
TEST(Scenario, MissingFile) { EXPECT_THROW(loadScenario("/nonexistent/s.yaml"), ConfigError); }

TEST(Scenario, InitialStanceWidthIsOptional) {
  EXPECT_DOUBLE_EQ(parseScenario(stepText(), "step.yaml").initial_stance_width_m, 0.0);  // feet under the hip
  const Scenario stand = loadScenario(scenarioDir() + "/stand.yaml");
  EXPECT_DOUBLE_EQ(stand.initial_stance_width_m, 0.12);
  EXPECT_NE(stand.toJson().find("\"initial_stance_width_m\": 0.12"), std::string::npos) << stand.toJson();
}
TEST(Scenario, InitialStanceWidthOutOfRange) {
  expectError("initial_base_height_m: 0.42", "initial_base_height_m: 0.42\ninitial_stance_width_m: 0.6",
              "initial_stance_width_m");
}
