// Strict loading of config/sim.yaml and terrain files; terrain heights.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "common/strict_yaml.hpp"
#include "sim_test_support.hpp"
#include "tests/support/config_test_support.hpp"

using namespace mft::sim;
using mft::config::ConfigError;

namespace {
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SimConfig, LoadsShippedOptions) {
  const SimOptions o = test::options();
  EXPECT_EQ(o.substeps, 1);
  EXPECT_DOUBLE_EQ(o.control_period_s, 0.001);
  EXPECT_EQ(o.loop_closure, LoopClosureJoint::Ball);
  EXPECT_FALSE(o.noise.enabled);
}

TEST(SimConfig, RejectsUnknownAndMissingKeys) {
  const std::string text = mft::test::readTextFile(std::string(MFT_CONFIG_DIR) + "/sim.yaml");
  const std::string unknown = text + "\nsurprise: 1\n";
  EXPECT_NE(errorOf([&] { parseSimOptions(unknown, "x.yaml"); }).find("surprise"), std::string::npos);
  std::string missing = text;
  missing.replace(missing.find("substeps: 1"), 11, "");
  EXPECT_NE(errorOf([&] { parseSimOptions(missing, "x.yaml"); }).find("substeps"), std::string::npos);
  std::string bad = text;
  bad.replace(bad.find("loop_closure: ball"), 18, "loop_closure: glue");
  EXPECT_NE(errorOf([&] { parseSimOptions(bad, "x.yaml"); }).find("world.loop_closure"), std::string::npos);
}

TEST(SimConfig, ActuatorModels) {
  const std::string text = mft::test::readTextFile(std::string(MFT_CONFIG_DIR) + "/sim.yaml");
  const std::string line = "  model: " + std::string(test::options().actuator_model == ActuatorModel::SeaMotor ? "sea_motor" : "sea");
  for (const auto& [name, model] : {std::pair<std::string, ActuatorModel>{"sea", ActuatorModel::Sea},
                                    {"sea_motor", ActuatorModel::SeaMotor}, {"ideal", ActuatorModel::Ideal}}) {
    std::string t = text;
    t.replace(t.find(line), line.size(), "  model: " + name);
    EXPECT_EQ(parseSimOptions(t, "x.yaml").actuator_model, model) << name;
  }
  std::string bad = text;
  bad.replace(bad.find(line), line.size(), "  model: magic");
  EXPECT_NE(errorOf([&] { parseSimOptions(bad, "x.yaml"); }).find("actuators.model"), std::string::npos);
  // The motor model's keys are required whichever model is chosen.
  std::string missing = text;
  const std::string damping = "reflected_damping_Nmsprad: 0.5";
  missing.replace(missing.find(damping), damping.size(), "");
  EXPECT_NE(errorOf([&] { parseSimOptions(missing, "x.yaml"); }).find("reflected_damping_Nmsprad"), std::string::npos);
  std::string period = text;
  const std::string loop = "torque_loop_period_s: 1.0e-4";
  period.replace(period.find(loop), loop.size(), "torque_loop_period_s: 0");
  EXPECT_NE(errorOf([&] { parseSimOptions(period, "x.yaml"); }).find("torque_loop_period_s"), std::string::npos);
}

TEST(SimConfig, TerrainIsStrictPerSegment) {
  const std::string head = "schema_version: 1\nstart_x_m: 0\nstart_height_m: 0\n";
  EXPECT_NE(errorOf([&] { parseTerrain(head + "terrain:\n  - {type: board, length_m: 1}\n", "t.yaml"); })
                .find("t.yaml: terrain[0]: height_m"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseTerrain(head + "terrain:\n  - {type: flat, length_m: 1, colour: red}\n", "t.yaml"); })
                .find("colour"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseTerrain(head + "terrain:\n  - {type: lava, length_m: 1}\n", "t.yaml"); }).find("lava"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { parseTerrain(head + "extra: 2\nterrain: []\n", "t.yaml"); }).find("extra"), std::string::npos);
  EXPECT_NE(errorOf([&] { parseTerrain("schema_version: 1\nstart_x_m: 0\nstart_height_m: 0\n", "t.yaml"); }).find("terrain"),
            std::string::npos);
}

TEST(SimConfig, CourseHeights) {
  const Terrain t = test::terrainFile("course.yaml");
  ASSERT_EQ(t.segments.size(), 6u);
  EXPECT_DOUBLE_EQ(t.heightAt(0.5), 0.0);
  EXPECT_DOUBLE_EQ(t.heightAt(1.3), 0.03);      // on the board
  EXPECT_DOUBLE_EQ(t.frictionAt(1.3), 0.5);
  EXPECT_DOUBLE_EQ(t.heightAt(2.0), 0.0);
  EXPECT_NEAR(t.heightAt(3.6), 1.0 * std::tan(6.0 * M_PI / 180.0), 1e-12);  // middle of the slope
  EXPECT_NEAR(t.endHeight(), 2.0 * std::tan(6.0 * M_PI / 180.0), 1e-12);
  const TerrainSegment& rough = t.segments[4];
  double top = 0.0;
  for (double s : rough.samples) top = std::max(top, s);
  EXPECT_GT(top, 0.015);
  EXPECT_LE(top, 0.02);
  EXPECT_EQ(loadTerrain(std::string(MFT_CONFIG_DIR) + "/terrain/flat.yaml").segments.size(), 0u);
}
