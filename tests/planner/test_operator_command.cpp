// Command gate: limits derived from the robot, rejection with a reason, last valid command stays in force.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/strict_yaml.hpp"
#include "model/robot_description.hpp"
#include "planner/operator_command.hpp"

using namespace mft::planner;

namespace {
mft::model::RobotDescription robot() { return mft::model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }
CommandParams params() {
  CommandParams p;
  p.height_margin_m = 0.03;
  p.height_window_m = {0.0, 10.0};  // let the reach range decide
  p.max_speed_mps = 0.6;
  return p;
}
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }
}  // namespace

TEST(CommandLimits, HeightRangeComesFromTheLegLengths) {
  const auto d = robot();
  const auto lim = commandLimits(d, params(), "planner.yaml");
  EXPECT_NEAR(lim.height_min_m, std::abs(d.shank.length_m - d.thigh.length_m) + 0.03, 1e-12);  // 0.07
  EXPECT_NEAR(lim.height_max_m, d.thigh.length_m + d.shank.length_m - 0.03, 1e-12);            // 0.45
  auto p = params();
  p.height_window_m = {0.30, 0.42};
  const auto win = commandLimits(d, p, "planner.yaml");
  EXPECT_DOUBLE_EQ(win.height_min_m, 0.30);
  EXPECT_DOUBLE_EQ(win.height_max_m, 0.42);
}

TEST(CommandLimits, EmptyRangeIsAConfigError) {
  auto p = params();
  p.height_window_m = {0.50, 0.60};  // above l1 + l2 - margin
  try {
    commandLimits(robot(), p, "planner.yaml");
    FAIL();
  } catch (const mft::config::ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "planner.yaml")) << e.what();
    EXPECT_TRUE(contains(e.what(), "height_window_m")) << e.what();
  }
}

TEST(CommandGate, RejectsWithAReasonAndKeepsTheLastValidCommand) {
  const auto lim = commandLimits(robot(), params(), "planner.yaml");
  CommandGate gate(lim, {0.42, 0.0, LocomotionMode::Stand});

  auto r = gate.submit({0.40, 0.3, LocomotionMode::Walk});
  EXPECT_TRUE(r.accepted);
  EXPECT_TRUE(r.reason.empty());
  EXPECT_DOUBLE_EQ(gate.current().z_cmd, 0.40);

  struct Bad {
    OperatorCommand cmd;
    const char* reason;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const Bad bad[] = {
      {{0.47, 0.0, LocomotionMode::Walk}, "outside the reachable range"},   // beyond l1 + l2 - margin
      {{0.05, 0.0, LocomotionMode::Walk}, "outside the reachable range"},   // below |l2 - l1| + margin
      {{0.40, 0.61, LocomotionMode::Walk}, "beyond the limit"},
      {{0.40, -0.7, LocomotionMode::Walk}, "beyond the limit"},
      {{nan, 0.0, LocomotionMode::Walk}, "height command is not a finite number"},
      {{0.40, nan, LocomotionMode::Walk}, "speed command is not a finite number"},
      {{0.40, inf, LocomotionMode::Walk}, "speed command is not a finite number"},
      {{0.40, 0.0, static_cast<LocomotionMode>(7)}, "unknown locomotion mode"},
  };
  for (const auto& b : bad) {
    r = gate.submit(b.cmd);
    EXPECT_FALSE(r.accepted);
    EXPECT_TRUE(contains(r.reason, b.reason)) << r.reason;
    EXPECT_DOUBLE_EQ(gate.current().z_cmd, 0.40);
    EXPECT_DOUBLE_EQ(gate.current().v_cmd, 0.3);
    EXPECT_EQ(gate.current().mode, LocomotionMode::Walk);
  }
  EXPECT_EQ(gate.rejectedCount(), std::size(bad));

  r = gate.submit({0.38, -0.2, LocomotionMode::StepInPlace});
  EXPECT_TRUE(r.accepted);
  EXPECT_DOUBLE_EQ(gate.current().z_cmd, 0.38);
  EXPECT_EQ(gate.current().mode, LocomotionMode::StepInPlace);
}

TEST(CommandGate, InvalidInitialCommandIsAConfigError) {
  const auto lim = commandLimits(robot(), params(), "planner.yaml");
  EXPECT_THROW(CommandGate(lim, {0.9, 0.0, LocomotionMode::Stand}), mft::config::ConfigError);
}
