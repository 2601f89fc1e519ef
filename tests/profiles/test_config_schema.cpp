// The configuration schema (common/config_schema.hpp): every numeric key of every shipped file has a physical
// range that the loaders, live tuning and mft-cmd --set enforce, text is not a number, and the reference
// table in docs/reference/config-reference.md is the schema's.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "chain/closed_loop.hpp"
#include "chain/scenario.hpp"
#include "common/config_schema.hpp"
#include "common/json_writer.hpp"
#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"
#include "planner/planner_config.hpp"
#include "planner/planner_tuning.hpp"
#include "sim/terrain.hpp"

namespace mft {
namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& p) { return test::readTextFile(p.string()); }

std::string plannerText() { return readFile(fs::path(MFT_CONFIG_DIR) / "planner.yaml"); }

std::string overrideError(const std::string& key, const std::string& value) {
  try {
    planner::applyPlannerOverride(plannerText(), "planner.yaml (live change)", key, value);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string liveValueError(const std::string& stem, const std::string& key, const std::string& value) {
  try {
    config::checkLiveValue(stem, key, value, "--set");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

// Every shipped file, alone and under every shipped profile, reads without a range error; a key the schema
// does not list would fail here ("no range in the configuration schema").
TEST(ConfigSchema, ShippedFilesAndProfilesPass) {
  const std::string dir = MFT_CONFIG_DIR;
  EXPECT_NO_THROW(closedloop::loadConfigs(dir, {}));
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "profiles"))
    EXPECT_NO_THROW(closedloop::loadConfigs(dir, {e.path().stem().string()})) << e.path();
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "scenarios"))
    EXPECT_NO_THROW(chain::loadScenario(e.path().string())) << e.path();
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "terrain"))
    EXPECT_NO_THROW(sim::loadTerrain(e.path().string())) << e.path();
}

TEST(ConfigSchema, NonPhysicalPlannerValuesRefusedByTheLoader) {
  std::string text = plannerText();
  text.replace(text.find("lift_height_m: 0.06"), 19, "lift_height_m: 50");
  try {
    planner::parsePlannerConfig(text, "planner.yaml");
    FAIL() << "lift_height_m 50 accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("swing.lift_height_m: must lie in [0, 0.3] m (got 50)"), std::string::npos)
        << e.what();
  }
}

TEST(ConfigSchema, NonPhysicalValuesRefusedByLiveTuning) {
  EXPECT_NE(overrideError("swing.lift_height_m", "50").find("must lie in [0, 0.3] m (got 50)"), std::string::npos);
  EXPECT_NE(overrideError("foot_placement.k_v", "1e308").find("must lie in [0, 2] s (got 1e+308)"), std::string::npos);
  EXPECT_EQ(overrideError("foot_placement.k_v", "0.145"), "");
}

TEST(ConfigSchema, TextIsNotANumber) {
  EXPECT_NE(overrideError("foot_placement.k_v", "!!str 0.1").find("expected a number, got the text '0.1'"),
            std::string::npos);
  EXPECT_NE(overrideError("foot_placement.k_v", "\"0.1\"").find("expected a number"), std::string::npos);
  std::string text = plannerText();
  text.replace(text.find("height_window_m: [0.30, 0.46]"), 29, "height_window_m: [0.30, !!str 0.46]");
  EXPECT_THROW(planner::parsePlannerConfig(text, "planner.yaml"), config::ConfigError);
  text = plannerText();
  text.replace(text.find("k_p: 0.08"), 9, "k_p: \"0.08\"");
  EXPECT_THROW(planner::parsePlannerConfig(text, "planner.yaml"), config::ConfigError);
}

// mft-cmd --set checks the value before it is sent.
TEST(ConfigSchema, LiveValueCheckOfMftCmd) {
  EXPECT_NE(liveValueError("planner", "swing.lift_height_m", "50").find("must lie in [0, 0.3] m"), std::string::npos);
  EXPECT_NE(liveValueError("planner", "foot_placement.k_v", "1e308").find("must lie in [0, 2] s"), std::string::npos);
  EXPECT_NE(liveValueError("planner", "foot_placement.k_v", "1e999").find("must be finite"), std::string::npos);
  EXPECT_NE(liveValueError("planner", "foot_placement.k_v", "!!str 5").find("expected a number"), std::string::npos);
  EXPECT_NE(liveValueError("wbc", "gains.swing_foot.kp", "[300, 1e9]").find("must lie in"), std::string::npos);
  EXPECT_EQ(liveValueError("wbc", "gains.swing_foot.kp", "[300, 300]"), "");
  EXPECT_EQ(liveValueError("wbc", "variant", "sa"), "");  // not numeric: left to the service
}

// A Latin-1 byte in a text value was accepted and then written into summaries and JSON reports as invalid UTF-8.
TEST(ConfigText, Latin1IsRefusedAndJsonStaysUtf8) {
  std::string text = plannerText();
  text.replace(text.find("first_swing_leg: right"), 22, "first_swing_leg: r\xe9ght");
  try {
    planner::parsePlannerConfig(text, "planner.yaml");
    FAIL() << "a Latin-1 byte was accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("gait.first_swing_leg: not UTF-8 text (byte 1 is 0xe9)"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(config::jsonEscape("caf\xe9 \xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80 \xc0\xaf"),
            "caf\\ufffd \xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80 \\ufffd\\ufffd");
  // A message quoting a foreign file's bytes: whole UTF-8 sequences (U+0533 here) and printable ASCII kept,
  // every other byte (a control byte, a lead byte without its continuation, DEL, newline) as \xNN.
  EXPECT_EQ(config::printableText("a mrp\xd4\xb3\x0f\xcf caf\xc3\xa9\x7f\n"),
            "a mrp\xd4\xb3\\x0f\\xcf caf\xc3\xa9\\x7f\\x0a");
  EXPECT_TRUE(config::isUtf8(config::printableText("\xff\xfe\xc0\xaf\xed\xa0\x80")));
  EXPECT_TRUE(config::isUtf8("\xc3\xa9"));
  EXPECT_FALSE(config::isUtf8("\xed\xa0\x80"));  // a UTF-16 surrogate
}

TEST(ConfigSchema, ListEntriesUseTheirListRange) {
  const auto* r = config::findKeyRange("scenario", "commands[12].v_cmd_mps");
  ASSERT_NE(r, nullptr);
  EXPECT_DOUBLE_EQ(r->hi, 3.0);
  EXPECT_EQ(config::findKeyRange("planner", "swing.no_such_key"), nullptr);
}

// docs/reference/config-reference.md holds the generated table between two markers; MFT_UPDATE_SCHEMA_DOC=1 rewrites it.
TEST(ConfigSchema, DocsTableIsTheSchema) {
  const fs::path path = fs::path(MFT_CONFIG_DIR) / ".." / "docs" / "reference" / "config-reference.md";
  std::string doc = readFile(path);
  const std::string begin = "<!-- schema begin -->\n", end = "<!-- schema end -->";
  const auto b = doc.find(begin), e = doc.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  const std::string table = doc.substr(b + begin.size(), e - b - begin.size());
  if (std::getenv("MFT_UPDATE_SCHEMA_DOC") && table != config::schemaMarkdown()) {
    doc.replace(b + begin.size(), table.size(), config::schemaMarkdown());
    std::ofstream(path) << doc;
    return;
  }
  EXPECT_EQ(table, config::schemaMarkdown()) << "regenerate: MFT_UPDATE_SCHEMA_DOC=1 build/release/tests/profiles/test_profiles "
                                                "--gtest_filter=ConfigSchema.DocsTableIsTheSchema";
}

}  // namespace
}  // namespace mft
