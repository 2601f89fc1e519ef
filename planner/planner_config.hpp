#pragma once
// Planner parameters, loaded strictly from config/planner.yaml (units in the key names there).
#include <array>
#include <string>

#include "planner/plan_output.hpp"

namespace mft::planner {

struct GaitParams {
  double step_duration_s = 0.35;     // nominal swing (single support) duration T
  double double_support_s = 0.0;     // both feet in stance between two steps
  double min_touchdown_phase = 0.6;  // a swing-foot contact before this phase is not a touchdown
  double max_extension_s = 0.15;     // late touchdown: longest extension of a swing before the swap is forced
  int first_swing_leg = model::kRightLeg;
};

struct SwingParams {
  double lift_height_m = 0.06;       // apex above the ground height, at mid-swing
  double touchdown_speed_mps = 0.2;  // downward speed at the end of the nominal swing, kept while extended
  double replan_until_phase = 0.8;   // (19) is re-evaluated every tick until this phase, then frozen
  double late_replan_speed_mps = 1.0;  // late touchdown: the foot moves toward (19) re-planned now (0 = frozen)
};

struct FootPlacementParams {
  double k_v = 0.16;           // (19) [s]
  double k_p = 0.08;           // (19) [s]
  double max_offset_m = 0.25;  // |target - predicted pre-impact CoM x| is clamped to this (leg reach)
};

struct CommandParams {
  double height_margin_m = 0.03;              // reach range [|l2-l1| + margin, l1 + l2 - margin]
  std::array<double, 2> height_window_m{0.30, 0.46};  // operating window, intersected with the reach range
  double max_speed_mps = 0.6;                 // |v_cmd| limit
  double height_rate_mps = 0.1;               // rate limit of the height reference toward the command
  double initial_height_m = 0.42;             // the command in force before any operator command
  double initial_speed_mps = 0.0;
  LocomotionMode initial_mode = LocomotionMode::Stand;
};

struct PlannerConfig {
  std::string source_file;
  GaitParams gait;
  SwingParams swing;
  FootPlacementParams placement;
  CommandParams command;
};

// Throw mft::config::ConfigError naming the file and key.
PlannerConfig loadPlannerConfig(const std::string& path);
PlannerConfig parsePlannerConfig(const std::string& yaml_text, const std::string& origin);

// "stand" | "step_in_place" | "walk"; false if unknown.
bool parseLocomotionMode(const std::string& text, LocomotionMode* mode);
const char* toString(LocomotionMode mode);

}  // namespace mft::planner
