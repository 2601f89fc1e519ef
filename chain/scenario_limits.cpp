#include "chain/scenario_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/strict_yaml.hpp"
#include "model/mft_criteria.hpp"
#include "planner/planner_config.hpp"

namespace mft::chain {

namespace {

// A length or speed with three decimals (mm, mm/s).
std::string n3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

[[noreturn]] void refuse(const Scenario& s, const std::string& key, const std::string& message) {
  throw config::ConfigError(s.source_file + ": " + key + ": " + message);
}

}  // namespace

void checkScenarioLimits(const Scenario& s, const model::RobotDescription& robot, const planner::CommandLimits& limits) {
  // The initial pose as mft-sim builds it: feet on flat ground, right foot half the stance width ahead of the
  // hip axis, left foot as far behind; each foot sinks by its static contact deflection.
  const auto leg = model::MftLegModel::from(robot);
  const double sink = 0.5 * robot.totalMass() * robot.gravity_mps2 / robot.contact_stiffness_Npm;
  model::Interval reach{-1e9, 1e9};
  for (const double x : {0.5 * s.initial_stance_width_m, -0.5 * s.initial_stance_width_m}) {
    const auto h = model::reachableBaseHeights(leg, x);
    reach = {std::max(reach.lo, h.lo - sink), std::min(reach.hi, h.hi - sink)};
  }
  if (!(reach.lo <= reach.hi))
    refuse(s, "initial_stance_width_m",
           n3(s.initial_stance_width_m) + " m: no base height puts both feet on the ground within the legs' reach at this "
           "stance width");
  if (!reach.contains(s.initial_base_height_m))
    refuse(s, "initial_base_height_m",
           n3(s.initial_base_height_m) + " m is outside the legs' reach: the robot can start at base heights in [" +
               n3(reach.lo) + ", " + n3(reach.hi) + "] m" +
               (s.initial_stance_width_m > 0.0 ? " (stance width " + n3(s.initial_stance_width_m) + " m)" : std::string()));

  double lowest = s.initial_base_height_m;
  for (std::size_t i = 0; i < s.commands.size(); ++i) {
    const auto& c = s.commands[i];
    const std::string key = "commands[" + std::to_string(i) + "]";
    if (!(c.z_cmd_m >= limits.height_min_m && c.z_cmd_m <= limits.height_max_m))
      refuse(s, key + ".z_cmd_m",
             n3(c.z_cmd_m) + " m is outside what the planner accepts: [" + n3(limits.height_min_m) + ", " +
                 n3(limits.height_max_m) + "] m (the legs' reach intersected with planner.yaml command.height_window_m)");
    if (!(std::abs(c.v_cmd_mps) <= limits.max_speed_mps))
      refuse(s, key + ".v_cmd_mps",
             n3(c.v_cmd_mps) + " m/s is beyond what the planner accepts: |v| <= " + n3(limits.max_speed_mps) +
                 " m/s (planner.yaml command.max_speed_mps)");
    lowest = std::min(lowest, c.z_cmd_m);
  }
  if (!(s.fall_base_height_m < lowest))
    refuse(s, "fall.base_height_below_m",
           n3(s.fall_base_height_m) + " m is not below the lowest base height the run starts at or is commanded to (" +
               n3(lowest) + " m): the run would count as a fall at once");
}

void checkScenarioLimits(const Scenario& scenario, const model::RobotDescription& robot, const std::string& planner_yaml) {
  const auto planner_config = planner::loadPlannerConfig(planner_yaml);
  checkScenarioLimits(scenario, robot, planner::commandLimits(robot, planner_config.command, planner_config.source_file));
}

}  // namespace mft::chain
