// The robot description loader: the default file loads with the documented values, and every kind of bad
// file is refused with a message that names the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <vector>

#include "common/strict_yaml.hpp"
#include "model/robot_description.hpp"
#include "tests/support/config_test_support.hpp"

using mft::config::ConfigError;
using mft::model::loadRobotDescription;
using mft::model::parseRobotDescription;

namespace {
std::string defaultPath() { return std::string(MFT_CONFIG_DIR) + "/robot.yaml"; }
std::string defaultText() { return mft::test::readTextFile(defaultPath()); }
// Replaces the first match of `pattern` in the default file and expects a ConfigError mentioning `expect`.
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  mft::test::expectConfigError(defaultText(), pattern, replacement, "bad-robot.yaml", expect, parseRobotDescription);
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
TEST(RobotDescription, NegativeMassIsRefused) { expectError(R"(mass_kg: 0.50)", "mass_kg: -0.5", "leg.thigh.mass_kg: must lie in [0.01, 100] kg"); }
TEST(RobotDescription, ZeroLengthIsRefused) { expectError(R"(length_m: 0.26)", "length_m: 0", "leg.shank.length_m: must lie in [0.02, 2] m"); }
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

// Physical plausibility (issue 16, item 4): every quantity of robot.yaml has a range; a value just outside
// either end, and the absurd ones that once reached ODE (1e308, 1e-300), are refused with the key and the
// range in the message. One row per key: the line to change in config/robot.yaml, the range as the loader
// prints it, and a value below and above it (NaN where the range has no lower end worth testing).
struct PlausibilityRow {
  const char* line;      // regex of the line in the default file (the first match is replaced)
  const char* key_line;  // what replaces the value: "<indent>key: " (the value is appended)
  const char* key_path;  // as named in the error
  const char* range;     // "[lo, hi] unit" as printed
  std::vector<std::string> bad_values;
};

TEST(RobotDescription, EveryQuantityOutsideItsPlausibleRangeIsRefusedWithTheRange) {
  const std::vector<PlausibilityRow> rows = {
      {R"(gravity_mps2: 9.81)", "gravity_mps2: ", "gravity_mps2", "[1, 30] m/s^2", {"0.5", "31", "1e308"}},
      {R"(  mass_kg: 16.4)", "  mass_kg: ", "torso.mass_kg", "[0.5, 500] kg", {"1e-300", "0.4", "501", "1e308"}},
      {R"(  com_m: \[0.0, 0.05\])", "  com_m: ", "torso.com_m", "[-1, 1] m", {"[0.0, 1.5]", "[-1.5, 0.05]"}},
      {R"(  inertia_kgm2: 0.20)", "  inertia_kgm2: ", "torso.inertia_kgm2", "[0.0001, 100] kg m^2", {"1e-5", "101"}},
      {R"(  size_m: \[0.25, 0.15\])", "  size_m: ", "torso.size_m", "[0.01, 3] m", {"[0.25, 0.0]", "[4.0, 0.15]"}},
      {R"(  imu_position_m: \[0.0, 0.05\])", "  imu_position_m: ", "torso.imu_position_m", "[-1, 1] m", {"[2.0, 0.05]"}},
      {R"(  hip_spacing_m: 0.0)", "  hip_spacing_m: ", "leg.hip_spacing_m", "[0, 1] m", {"-0.01", "1.5"}},
      {R"(    length_m: 0.22)", "    length_m: ", "leg.thigh.length_m", "[0.02, 2] m", {"0.01", "2.5"}},
      {R"(    mass_kg: 0.50)", "    mass_kg: ", "leg.thigh.mass_kg", "[0.01, 100] kg", {"1e-300", "0.001", "101", "1e308"}},
      {R"(    inertia_kgm2: 2.02e-3)", "    inertia_kgm2: ", "leg.thigh.inertia_kgm2", "[1e-07, 10] kg m^2", {"1e-9", "11"}},
      {R"(    length_m: 0.26)", "    length_m: ", "leg.shank.length_m", "[0.02, 2] m", {"0.0", "3"}},
      {R"(    mass_kg: 1.15)", "    mass_kg: ", "leg.shank.mass_kg", "[0.01, 100] kg", {"1e-300", "1e308"}},
      {R"(    inertia_kgm2: 6.48e-3)", "    inertia_kgm2: ", "leg.shank.inertia_kgm2", "[1e-07, 10] kg m^2", {"0", "20"}},
      {R"(  foot_radius_m: 0.0)", "  foot_radius_m: ", "leg.foot_radius_m", "[0, 0.2] m", {"-0.1", "0.3"}},
      {R"(  knee_hard_stop_margin_rad: 0.05)", "  knee_hard_stop_margin_rad: ", "joint_limits.knee_hard_stop_margin_rad",
       "[0, 0.5] rad", {"-0.01", "0.6"}},
      {R"(  gear_ratio: 30.0)", "  gear_ratio: ", "actuator.gear_ratio", "[1, 1000]", {"0.5", "1e4"}},
      {R"(  rotor_inertia_kgm2: 1.0e-4)", "  rotor_inertia_kgm2: ", "actuator.rotor_inertia_kgm2", "[1e-08, 0.1] kg m^2",
       {"1e-300", "1"}},
      {R"(  motor_peak_torque_Nm: 1.7454)", "  motor_peak_torque_Nm: ", "actuator.motor_peak_torque_Nm",
       "[0.001, 1000] N m", {"1e-4", "1e308"}},
      {R"(  gearbox_efficiency: 1.0)", "  gearbox_efficiency: ", "actuator.gearbox_efficiency", "[0.05, 1]", {"0.01", "1.1"}},
      {R"(  output_speed_limit_radps: 20.0)", "  output_speed_limit_radps: ", "actuator.output_speed_limit_radps",
       "[0.1, 1000] rad/s", {"0.01", "2000"}},
      {R"(    spring_stiffness_Nmprad: 1000.0)", "    spring_stiffness_Nmprad: ", "actuator.sea.spring_stiffness_Nmprad",
       "[1, 1e+07] N m/rad", {"0.5", "1e8"}},
      {R"(    natural_frequency_radps: 233.5)", "    natural_frequency_radps: ", "actuator.sea.natural_frequency_radps",
       "[1, 100000] rad/s", {"0.5", "1e6"}},
      {R"(    damping_ratio: 1.0)", "    damping_ratio: ", "actuator.sea.damping_ratio", "[0.05, 10]", {"0.01", "11"}},
      {R"(    settling_time_s: 0.025)", "    settling_time_s: ", "actuator.sea.settling_time_s", "[0.0001, 10] s", {"1e-5", "11"}},
      {R"(  friction_coefficient: 0.8)", "  friction_coefficient: ", "contact.friction_coefficient", "[0.01, 5]", {"0.001", "6"}},
      {R"(  stiffness_Npm: 2.0e5)", "  stiffness_Npm: ", "contact.stiffness_Npm", "[100, 1e+09] N/m", {"50", "1e10"}},
      {R"(  damping_Nspm: 2.0e3)", "  damping_Nspm: ", "contact.damping_Nspm", "[0, 1e+07] N s/m", {"-1", "1e8"}},
  };
  for (const auto& row : rows) {
    // The default value itself loads (the row matches a real line).
    const std::string line_re = std::string("\n") + row.line + "[^\n]*";
    ASSERT_TRUE(std::regex_search(defaultText(), std::regex(line_re))) << row.line;
    for (const auto& bad : row.bad_values) {
      SCOPED_TRACE(std::string(row.key_path) + " = " + bad);
      expectError(line_re, std::string("\n") + row.key_line + bad, std::string(row.key_path) + ": ");
      expectError(line_re, std::string("\n") + row.key_line + bad, row.range);
    }
  }
}
