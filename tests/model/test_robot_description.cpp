// The robot description loader: the default file loads with the documented values, and every kind of bad
// file is refused with a message that names the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "model/config/strict_yaml.hpp"
#include "model/robot_description.hpp"

using mft::config::ConfigError;
using mft::model::loadRobotDescription;
using mft::model::parseRobotDescription;

namespace {
std::string defaultPath() { return std::string(MFT_CONFIG_DIR) + "/robot.yaml"; }
std::string defaultText() {
  std::ifstream in(defaultPath());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
// Replaces the first match of `pattern` in the default file and expects a ConfigError mentioning `expect`.
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  const std::string text = std::regex_replace(defaultText(), std::regex(pattern), replacement,
                                              std::regex_constants::format_first_only);
  ASSERT_NE(text, defaultText()) << "pattern did not match: " << pattern;
  try {
    parseRobotDescription(text, "bad-robot.yaml");
    FAIL() << "expected a ConfigError containing '" << expect << "'";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad-robot.yaml"), std::string::npos) << msg;
    EXPECT_NE(msg.find(expect), std::string::npos) << msg;
  }
}
}  // namespace

TEST(RobotDescription, DefaultFileHasTheWorkedParameterSet) {
  const auto d = loadRobotDescription(defaultPath());
  EXPECT_DOUBLE_EQ(d.thigh.length_m, 0.22);
  EXPECT_DOUBLE_EQ(d.shank.length_m, 0.26);
  EXPECT_DOUBLE_EQ(d.hip_spacing_m, 0.0);
  EXPECT_NEAR(d.legMass(), 3.30, 1e-12);
  EXPECT_NEAR(d.totalMass(), 23.0, 1e-12);
  EXPECT_NEAR(d.actuator.outputPeakTorque(), 52.362, 1e-9);
  EXPECT_NEAR(d.actuator.motor_peak_torque_Nm / std::sqrt(d.actuator.rotor_inertia_kgm2), 174.54, 1e-9);
  EXPECT_DOUBLE_EQ(d.rear_hip_rad.lo, -1.90);
  EXPECT_DOUBLE_EQ(d.fore_hip_rad.hi, 1.90);
  EXPECT_NE(d.checksum, 0u);
}

TEST(RobotDescription, ChecksumIgnoresFormattingButNotValues) {
  const auto a = parseRobotDescription(defaultText(), "a");
  const auto b = parseRobotDescription("# extra comment\n" + defaultText(), "b");
  EXPECT_EQ(a.checksum, b.checksum);
  const auto c = parseRobotDescription(std::regex_replace(defaultText(), std::regex("length_m: 0.26"), "length_m: 0.27"), "c");
  EXPECT_NE(a.checksum, c.checksum);
}

TEST(RobotDescription, MissingKeyIsNamed) { expectError(R"(\n  inertia_kgm2: 0.20[^\n]*)", "", "torso.inertia_kgm2: missing key"); }
TEST(RobotDescription, UnknownKeyIsNamed) { expectError(R"(gravity_mps2: 9.81)", "gravity_mps2: 9.81\nbanana: 1", "unknown key banana"); }
TEST(RobotDescription, UnknownNestedKeyIsNamed) {
  expectError(R"(    length_m: 0.22)", "    length_m: 0.22\n    colour: red", "leg.thigh.colour");
}
TEST(RobotDescription, WrongTypeIsNamed) { expectError(R"(mass_kg: 16.4)", "mass_kg: heavy", "torso.mass_kg: expected a number"); }
TEST(RobotDescription, NegativeMassIsRefused) { expectError(R"(mass_kg: 0.50)", "mass_kg: -0.5", "leg.thigh.mass_kg: must be > 0"); }
TEST(RobotDescription, ZeroLengthIsRefused) { expectError(R"(length_m: 0.26)", "length_m: 0", "leg.shank.length_m: must be > 0"); }
TEST(RobotDescription, WrongListSizeIsRefused) { expectError(R"(com_m: \[0.0, 0.05\])", "com_m: [0.0]", "torso.com_m: expected 2 numbers"); }
TEST(RobotDescription, InvertedLimitsAreRefused) {
  expectError(R"(rear_hip_rad: \[-1.90, 0.35\])", "rear_hip_rad: [0.35, -1.90]", "joint_limits.rear_hip_rad");
}
TEST(RobotDescription, ComOutsideLinkIsRefused) {
  expectError(R"(com_from_knee_m: 0.117)", "com_from_knee_m: 0.5", "leg.shank.com_from_knee_m");
}
TEST(RobotDescription, MissingFileIsAClearError) {
  try {
    loadRobotDescription("/nonexistent/robot.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.yaml: cannot open"), std::string::npos) << e.what();
  }
}
TEST(RobotDescription, MalformedYamlIsAClearError) {
  EXPECT_THROW(parseRobotDescription("torso: [1, 2\n", "broken.yaml"), ConfigError);
  EXPECT_THROW(parseRobotDescription("- just\n- a list\n", "list.yaml"), ConfigError);
}
