// The chain's scenario-driven pieces: which commands are due when, the height in force, and the simulator node
// playing a scenario push (at a time) and reporting it to the recovery window and to the caller.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "chain/command_schedule.hpp"
#include "chain/sim_node.hpp"
#include "model/robot_description.hpp"
#include "sim/sim_options.hpp"
#include "sim/terrain.hpp"

using namespace mft;

namespace {

chain::Scenario scenario() {
  chain::Scenario s;
  s.name = "nodes";
  s.duration_s = 0.1;
  s.controller = "mft";
  s.estimator = "kalman";
  s.terrain = "flat";
  s.initial_base_height_m = 0.42;
  s.initial_stance_width_m = 0.12;
  s.fall_base_height_m = 0.25;
  s.fall_pitch_rad = 0.8;
  s.commands = {{0.0, chain::LocomotionMode::Stand, 0.42, 0.0}, {0.05, chain::LocomotionMode::StepInPlace, 0.40, 0.0}};
  return s;
}

}  // namespace

TEST(CommandSchedule, GivesEachCommandOnceFromTheTickItIsDue) {
  const auto s = scenario();
  chain::CommandSchedule schedule(s.commands);
  int given = 0;
  double last_z = 0.0;
  const auto apply = [&](const chain::ScenarioCommand& c) {
    ++given;
    last_z = c.z_cmd_m;
  };
  schedule.applyDue(0.0, apply);
  EXPECT_EQ(given, 1);
  schedule.applyDue(0.049, apply);
  EXPECT_EQ(given, 1);
  schedule.applyDue(0.05 - 1e-10, apply);  // within the planner's 1e-9 s tolerance
  EXPECT_EQ(given, 2);
  EXPECT_DOUBLE_EQ(last_z, 0.40);
  schedule.applyDue(1.0, apply);
  EXPECT_EQ(given, 2);
  schedule.restart();
  schedule.applyDue(1.0, apply);
  EXPECT_EQ(given, 4);
  EXPECT_EQ(chain::toOperatorCommand(s.commands[1]).mode, planner::LocomotionMode::StepInPlace);
}

TEST(CommandSchedule, HeightInForce) {
  const auto s = scenario();
  EXPECT_DOUBLE_EQ(chain::commandedHeight(s, 0.0), 0.42);
  EXPECT_DOUBLE_EQ(chain::commandedHeight(s, 0.0499), 0.42);
  EXPECT_DOUBLE_EQ(chain::commandedHeight(s, 0.05), 0.40);
}

TEST(SimNode, PlaysAScenarioPushAtItsTimeAndReportsIt) {
  auto s = scenario();
  s.pushes.push_back({2.0, 0.02, -1});  // 2 N s forward at t = 0.02 s
  const std::string dir = MFT_CONFIG_DIR;
  const auto robot = model::loadRobotDescription(dir + "/robot.yaml");
  const auto options = sim::loadSimOptions(dir + "/sim.yaml");
  chain::SimNode node(robot, options, sim::loadTerrain(dir + "/terrain/flat.yaml"), s, 1.0);
  EXPECT_EQ(node.ticksTotal(), static_cast<std::uint64_t>(std::llround(0.1 / options.control_period_s)));
  EXPECT_NEAR(node.truth().q[model::kBaseZ], 0.42, 0.01);
  model::ActuatorCommand hold;
  hold.mode = model::CommandMode::Damping;
  std::uint64_t applied_at_tick = 0;
  while (node.tick() < node.ticksTotal()) {
    const std::uint64_t k = node.tick();
    hold.tick = k;
    EXPECT_FALSE(node.step(hold)) << "fell at tick " << k;
    if (node.firstNewImpulse() < node.simulator().stats().impulses.size()) applied_at_tick = k;
  }
  ASSERT_EQ(node.simulator().stats().impulses.size(), 1u);
  EXPECT_NEAR(node.simulator().stats().impulses[0].time_s, 0.02, options.control_period_s);
  EXPECT_EQ(applied_at_tick, static_cast<std::uint64_t>(std::llround(0.02 / options.control_period_s)));
  const auto record = node.recovery().record();
  EXPECT_EQ(record.impulses, 1);
  EXPECT_DOUBLE_EQ(record.push_impulse_Ns, 2.0);
  EXPECT_FALSE(node.monitor().fell());
}

// A push at a gait phase fires in the first step that starts after its time with its stance leg, at the tick
// the planner's phase reaches it: not in the step in progress when armed, not on the other stance leg, and never
// without the planner's phase.
TEST(SimNode, PlaysAPushAtAGaitPhaseWhereThePlannerSaysItIs) {
  auto s = scenario();
  chain::ScenarioPush push{4.0, 0.01, -1};
  push.at_phase = 0.5;
  push.stance_leg = 1;  // left stance
  s.pushes.push_back(push);
  const std::string dir = MFT_CONFIG_DIR;
  const auto robot = model::loadRobotDescription(dir + "/robot.yaml");
  const auto options = sim::loadSimOptions(dir + "/sim.yaml");
  chain::SimNode node(robot, options, sim::loadTerrain(dir + "/terrain/flat.yaml"), s, 1.0);
  model::ActuatorCommand hold;
  hold.mode = model::CommandMode::Damping;
  // A made-up gait of 20-tick steps, left stance on odd steps: the phase is the place in the step.
  const auto gaitAt = [](std::uint64_t k) {
    const std::uint64_t step = 1 + k / 20;
    return chain::GaitPhase{true, step, static_cast<double>(k % 20) / 20.0, step % 2 == 1 ? 1 : 0};
  };
  std::uint64_t applied_at = 0;
  while (node.tick() < node.ticksTotal()) {
    const std::uint64_t k = node.tick();
    hold.tick = k;
    node.step(hold, k < 5 ? chain::GaitPhase{} : gaitAt(k));  // no phase known before tick 5
    if (node.firstNewImpulse() < node.simulator().stats().impulses.size()) applied_at = k;
  }
  // Armed at tick 10 (0.01 s) in step 1 (left stance, phase 0.5 already): that step does not count; step 2 is
  // right stance; step 3 (ticks 40-59) is the next left-stance step: phase 0.5 at tick 50.
  ASSERT_EQ(node.simulator().stats().impulses.size(), 1u);
  EXPECT_EQ(applied_at, 50u);
  EXPECT_FALSE(node.pushes().phasePushesWaiting());
  chain::SimNode blind(robot, options, sim::loadTerrain(dir + "/terrain/flat.yaml"), s, 1.0);
  while (blind.tick() < blind.ticksTotal()) blind.step(hold);
  EXPECT_TRUE(blind.simulator().stats().impulses.empty());
  EXPECT_TRUE(blind.pushes().phasePushesWaiting());
}

// The layer rule (docs/reference/architecture.md): the chain library includes no transport, no recording and nothing of
// services/, so a robot's bridge or the in-process loop can use it without them.
TEST(ChainLibrary, IncludesNoTransportNoRecordingNoServices) {
  const std::filesystem::path dir = std::filesystem::path(MFT_CONFIG_DIR).parent_path() / "chain";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto ext = entry.path().extension();
    if (ext != ".hpp" && ext != ".cpp") continue;
    ++files;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("#include", 0) != 0) continue;
      for (const char* banned : {"fastdds", "fastrtps", "mrpt", "idl/", "services/", "tools/"})
        EXPECT_EQ(line.find(banned), std::string::npos) << entry.path().filename() << ": " << line;
    }
  }
  EXPECT_GE(files, 20);
}
