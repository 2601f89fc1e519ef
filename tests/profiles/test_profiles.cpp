// The profile overlay (common/profiles.hpp): strict, composable in order, applied by every loader, and
// every shipped profile loads and states its reason.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "chain/closed_loop.hpp"
#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"
#include "chain/scenario.hpp"

namespace mft {
namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& p) { return test::readTextFile(p.string()); }

// A config folder with copies of the project's files and the given profile files.
class ProfileDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mft-profiles-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "profiles");
    for (const char* f : {"robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml"})
      fs::copy_file(fs::path(MFT_CONFIG_DIR) / f, dir_ / f);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void profile(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / "profiles" / (name + ".yaml")) << text;
  }
  std::string errorOf(const std::vector<std::string>& names) {
    try {
      closedloop::loadConfigs(dir_.string(), names);
    } catch (const config::ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(ProfileDir, OverlayReplacesLeavesAndNamesItself) {
  profile("a", "# test\nwbc:\n  weights:\n    slack: 7.0\n  sa:\n    rear_knee_rad: [0.2, 3.0]\nplanner:\n"
               "  foot_placement:\n    k_v: 0.15\n");
  const auto c = closedloop::loadConfigs(dir_.string(), {"a"});
  EXPECT_DOUBLE_EQ(c.wbc.weights.slack, 7.0);
  EXPECT_DOUBLE_EQ(c.wbc.sa.rear_knee_rad.lo, 0.2);
  EXPECT_DOUBLE_EQ(c.wbc.sa.rear_knee_rad.hi, 3.0);
  EXPECT_DOUBLE_EQ(c.planner.placement.k_v, 0.15);
  // Keys the profile does not name keep the base file's values.
  const auto base = closedloop::loadConfigs(dir_.string());
  EXPECT_DOUBLE_EQ(c.wbc.weights.contact_force, base.wbc.weights.contact_force);
  EXPECT_DOUBLE_EQ(c.wbc.sa.fore_knee_rad.lo, base.wbc.sa.fore_knee_rad.lo);
  EXPECT_NE(c.wbc.source_file.find("profiles a"), std::string::npos) << c.wbc.source_file;
  // The scope ended: a later load in this process sees the base files again.
  EXPECT_DOUBLE_EQ(wbc::loadWbcConfig((dir_ / "wbc.yaml").string()).weights.slack, base.wbc.weights.slack);
  EXPECT_TRUE(config::activeProfiles().empty());
}

TEST_F(ProfileDir, LaterProfilesWinInCommandLineOrder) {
  profile("a", "wbc:\n  weights:\n    slack: 10.0\n    base_x: 2.0\n");
  profile("b", "wbc:\n  weights:\n    slack: 20.0\n");
  const auto ab = closedloop::loadConfigs(dir_.string(), {"a", "b"});
  EXPECT_DOUBLE_EQ(ab.wbc.weights.slack, 20.0);
  EXPECT_DOUBLE_EQ(ab.wbc.weights.base_x, 2.0);
  const auto ba = closedloop::loadConfigs(dir_.string(), {"b", "a"});
  EXPECT_DOUBLE_EQ(ba.wbc.weights.slack, 10.0);
  // The scenario's profiles come first, then --profile values (comma lists allowed), each once.
  chain::Scenario s;
  s.profiles = {"b"};
  EXPECT_EQ(chain::runProfiles(s, {"a,b", "c"}), (std::vector<std::string>{"b", "a", "c"}));
}

TEST_F(ProfileDir, StrictOverlaysAreRefusedWithFileAndKey) {
  profile("typo", "wbc:\n  weights:\n    slak: 1.0\n");
  std::string e = errorOf({"typo"});
  EXPECT_NE(e.find("typo.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("wbc.weights.slak"), std::string::npos) << e;
  EXPECT_NE(e.find("no such key"), std::string::npos) << e;

  profile("stem", "wbcc:\n  weights:\n    slack: 1.0\n");
  e = errorOf({"stem"});
  EXPECT_NE(e.find("wbcc"), std::string::npos) << e;

  profile("kind", "wbc:\n  weights: 3\n");
  e = errorOf({"kind"});
  EXPECT_NE(e.find("wbc.weights"), std::string::npos) << e;
  EXPECT_NE(e.find("mapping"), std::string::npos) << e;

  // Types are checked by the loader itself, on the overlaid file, with the profile named.
  profile("type", "wbc:\n  weights:\n    slack: lots\n");
  e = errorOf({"type"});
  EXPECT_NE(e.find("weights.slack"), std::string::npos) << e;
  EXPECT_NE(e.find("profiles type"), std::string::npos) << e;

  e = errorOf({"missing"});
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
  e = errorOf({"../wbc"});
  EXPECT_NE(e.find("no path"), std::string::npos) << e;
  profile("a", "wbc:\n  weights:\n    slack: 1.0\n");
  e = errorOf({"a", "a"});
  EXPECT_NE(e.find("twice"), std::string::npos) << e;
}

TEST_F(ProfileDir, EffectiveTextIsWhatTheLoaderReads) {
  profile("a", "sim:\n  actuators:\n    model: ideal\n");
  const auto set = config::ProfileSet::load(dir_.string(), {"a"});
  const std::string text = set.applyToText("sim", readFile(dir_ / "sim.yaml"), "sim.yaml");
  EXPECT_EQ(sim::parseSimOptions(text, "recorded").actuator_model, sim::ActuatorModel::Ideal);
  EXPECT_EQ(set.applyToText("wbc", "x: 1\n", "wbc.yaml"), "x: 1\n");  // untouched files stay verbatim
  EXPECT_EQ(config::profileStemOf("/a/b/wbc.yaml"), "wbc");
  EXPECT_EQ(config::profileStemOf("/a/b/scenarios/walk.yaml"), "");
}

std::vector<std::string> shippedProfiles() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(MFT_CONFIG_DIR) / "profiles"))
    if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(ShippedProfiles, EachLoadsAndChangesSomething) {
  const auto names = shippedProfiles();
  ASSERT_GE(names.size(), 6u);
  const auto base = closedloop::loadConfigs(MFT_CONFIG_DIR);
  for (const auto& name : names) {
    SCOPED_TRACE(name);
    closedloop::Configs c;
    ASSERT_NO_THROW(c = closedloop::loadConfigs(MFT_CONFIG_DIR, {name}));
    const bool changed = c.wbc.weights.slack != base.wbc.weights.slack ||
                         c.wbc.weights.contact_force != base.wbc.weights.contact_force ||
                         c.wbc.weights.contact_force_rate != base.wbc.weights.contact_force_rate ||
                         c.wbc.sa.rear_knee_rad.lo != base.wbc.sa.rear_knee_rad.lo ||
                         c.wbc.contact.friction_fraction != base.wbc.contact.friction_fraction ||
                         c.planner.placement.k_v != base.planner.placement.k_v ||
                         c.sim.actuator_model != base.sim.actuator_model;
    EXPECT_TRUE(changed) << name << " changes none of the departures this test knows";
  }
  // All of them together (the project's setup before issue 15) compose without conflict.
  EXPECT_NO_THROW(closedloop::loadConfigs(MFT_CONFIG_DIR, names));
}

// Each shipped profile opens with comment lines naming itself and its reason, with a measurement or a named
// reference (docs/guide/profiles.md) behind it.
TEST(ShippedProfiles, EachStatesItsReason) {
  for (const auto& name : shippedProfiles()) {
    SCOPED_TRACE(name);
    const std::string text = readFile(fs::path(MFT_CONFIG_DIR) / "profiles" / (name + ".yaml"));
    std::string comments;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("#", 0) == 0) comments += line + "\n";
    EXPECT_EQ(text.rfind("# Profile " + name + ":", 0), 0u) << "the first line names the profile";
    EXPECT_NE(comments.find("Reason"), std::string::npos) << "no 'Reason' comment";
    EXPECT_NE(comments.find("docs/guide/profiles.md"), std::string::npos) << "no pointer to docs/guide/profiles.md";
    EXPECT_GE(std::count(comments.begin(), comments.end(), '\n'), 3) << "a reason in at least three comment lines";
  }
}

}  // namespace
}  // namespace mft
