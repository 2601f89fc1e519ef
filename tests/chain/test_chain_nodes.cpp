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

// The layer rule (docs/architecture.md): the chain library includes no transport, no recording and nothing of
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
