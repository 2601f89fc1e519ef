#pragma once
// Live tuning of the planner (docs/guide/live-tuning.md): a swing, foot-placement or height-rate key of
// config/planner.yaml changed while the planner runs. Judged off the control loop by config/planner.yaml's own
// strict loader (applyPlannerOverride); swapped in at a tick boundary by MotionPlanner::setTuning (a copy of a
// few doubles, allocation-free). Gait timing and command limits are structure, not tunable.
#include <string>
#include <vector>

#include "common/live_tuning.hpp"
#include "planner/planner_config.hpp"

namespace mft::planner {

struct PlannerTuning {
  SwingParams swing;
  FootPlacementParams placement;
  double height_rate_mps = 0.1;
};
inline PlannerTuning tuningOf(const PlannerConfig& c) { return {c.swing, c.placement, c.command.height_rate_mps}; }

using PlannerOverride = config::ConfigOverride<PlannerConfig>;

// Sets `key` of config/planner.yaml to `value_yaml` in `yaml_text` (named `origin` in messages) and loads the
// result with parsePlannerConfig. Throws config::ConfigError with the loader's message for an unknown key or an
// invalid value, and for a valid key that is not tunable live (config/live_tuning.hpp).
PlannerOverride applyPlannerOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                                     const std::string& value_yaml);

}  // namespace mft::planner
