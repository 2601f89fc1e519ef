#pragma once
// A scenario against what this robot and this stack can do (the scenario loader alone only knows generic
// ranges): the initial pose inside the legs' reach (robot.yaml through the model library), every commanded
// height and speed inside what the planner accepts (the legs' reach intersected with planner.yaml's
// command window and speed limit, planner::commandLimits), and the fall height below the heights the run
// starts at and is commanded to (else the run "falls" at once). Used by `mft-sim --check-scenario`, which
// the supervisor runs before starting anything, and by every service at start-up.
#include <string>

#include "model/robot_description.hpp"
#include "planner/operator_command.hpp"
#include "chain/scenario.hpp"

namespace mft::chain {

// Throws config::ConfigError "<scenario file>: <key>: <value> is outside ... [lo, hi] ..." for the first
// value out of range.
void checkScenarioLimits(const Scenario& scenario, const model::RobotDescription& robot,
                         const planner::CommandLimits& limits);

// The same with the planner's limits from `planner_yaml` (throws ConfigError for a bad planner.yaml too).
void checkScenarioLimits(const Scenario& scenario, const model::RobotDescription& robot,
                         const std::string& planner_yaml);

}  // namespace mft::chain
