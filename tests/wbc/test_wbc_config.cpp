// config/wbc.yaml: strict loading, Table I defaults, clear errors.
#include <gtest/gtest.h>

#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"
#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"

namespace mft::wbc {
namespace {

std::string projectYaml() { return mft::test::readTextFile(std::string(MFT_CONFIG_DIR) + "/wbc.yaml"); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string errorOf(const std::string& yaml) {
  try {
    parseWbcConfig(yaml, "test.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

// The paper's Table I (its departures are opt-in profiles, config/profiles/; tests/profiles checks all defaults).
TEST(WbcConfig, ProjectFileLoadsWithTableIWeights) {
  const WbcConfig c = loadWbcConfig(std::string(MFT_CONFIG_DIR) + "/wbc.yaml");
  EXPECT_EQ(c.variant, WbcVariant::Mft);
  EXPECT_DOUBLE_EQ(c.weights.base_z, 1.0);
  EXPECT_DOUBLE_EQ(c.weights.base_pitch, 1.0);
  EXPECT_DOUBLE_EQ(c.weights.swing_foot, 1.0);
  EXPECT_DOUBLE_EQ(c.weights.support_foot, 1e2);
  EXPECT_DOUBLE_EQ(c.weights.contact_force, 1e-3);
  EXPECT_DOUBLE_EQ(c.weights.contact_force_rate, 5e-2);
  EXPECT_DOUBLE_EQ(c.weights.slack, 1e3);
  // dt = 2 t_s = 0.05 s with the robot's SEA settling time.
  const WbcPolytope poly = test::testPolytope();
  WholeBodyController wbc(test::robot(), c, poly);
  EXPECT_NEAR(wbc.params().dt, 0.05, 1e-12);
  EXPECT_NEAR(wbc.params().tau_max[0], test::robot().actuator.outputPeakTorque(), 1e-12);
  // The struct defaults are the file's values (tests and tools may rely on either).
  const WbcConfig d;
  EXPECT_EQ(d.safety.hold_ticks, c.safety.hold_ticks);
  EXPECT_DOUBLE_EQ(d.gains.base_z.kp, c.gains.base_z.kp);
  EXPECT_DOUBLE_EQ(d.sa.rear_knee_rad.lo, c.sa.rear_knee_rad.lo);
  EXPECT_DOUBLE_EQ(d.contact.friction_fraction, c.contact.friction_fraction);
}

TEST(WbcConfig, VariantsParse) {
  for (const char* v : {"sa", "none", "mft"}) {
    const WbcConfig c = parseWbcConfig(replaced(projectYaml(), "variant: mft", std::string("variant: ") + v), "t");
    EXPECT_STREQ(toString(c.variant), v);
  }
}

TEST(WbcConfig, BadVariantIsAClearError) {
  const std::string e = errorOf(replaced(projectYaml(), "variant: mft", "variant: mpc"));
  EXPECT_NE(e.find("test.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("variant"), std::string::npos) << e;
  EXPECT_NE(e.find("mpc"), std::string::npos) << e;
  EXPECT_NE(e.find("mft, sa, none"), std::string::npos) << e;
}

TEST(WbcConfig, UnknownKeyIsAClearError) {
  const std::string e = errorOf(replaced(projectYaml(), "  slack: 1.0e3", "  slack: 1.0e3\n  slak: 2.0"));
  EXPECT_NE(e.find("slak"), std::string::npos) << e;
  EXPECT_NE(e.find("test.yaml"), std::string::npos) << e;
}

TEST(WbcConfig, MissingKeyAndBadValuesAreClearErrors) {
  std::string e = errorOf(replaced(projectYaml(), "  hold_ticks: 5", ""));
  EXPECT_NE(e.find("hold_ticks"), std::string::npos) << e;
  e = errorOf(replaced(projectYaml(), "contact_force: 1.0e-3", "contact_force: -1.0"));
  EXPECT_NE(e.find("contact_force"), std::string::npos) << e;
  e = errorOf(replaced(projectYaml(), "rear_knee_rad: [0.0, 3.141592653589793]", "rear_knee_rad: [3.0, 0.1]"));
  EXPECT_NE(e.find("rear_knee_rad"), std::string::npos) << e;
  e = errorOf(replaced(projectYaml(), "torque_limit_fraction: 1.0", "torque_limit_fraction: 1.5"));
  EXPECT_NE(e.find("torque_limit_fraction"), std::string::npos) << e;
}

TEST(WbcConfig, SaBoundsOutsideTheRobotAreRejected) {
  WbcConfig c = parseWbcConfig(replaced(projectYaml(), "fore_knee_rad: [-3.141592653589793, 0.0]",
                                        "fore_knee_rad: [-3.141592653589793, 0.2]"),
                               "test.yaml");
  try {
    validateWbcConfig(c, test::robot());
    FAIL() << "accepted a fore knee bound on the wrong side of 0";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("sa.fore_knee_rad"), std::string::npos) << e.what();
  }
  EXPECT_THROW(WholeBodyController(test::robot(), c, nullptr), config::ConfigError);
}

}  // namespace
}  // namespace mft::wbc
