#include "planner/planner_config.hpp"

#include "common/strict_yaml.hpp"

namespace mft::planner {
namespace {

using config::EnumName;
using config::StrictNode;

constexpr EnumName<model::Leg> kLegNames[] = {{model::kRightLeg, "right"}, {model::kLeftLeg, "left"}};
constexpr EnumName<LocomotionMode> kModeNames[] = {{LocomotionMode::Stand, "stand"},
                                                   {LocomotionMode::StepInPlace, "step_in_place"},
                                                   {LocomotionMode::Walk, "walk"}};

PlannerConfig read(StrictNode& root) {
  root.useSchema("planner");  // every number it reads is checked against its range (config_schema.hpp)
  PlannerConfig c;

  auto& gait = root.child("gait");
  c.gait.step_duration_s = gait.positive("step_duration_s");
  c.gait.double_support_s = gait.nonNegative("double_support_s");
  c.gait.min_touchdown_phase = gait.inRange("min_touchdown_phase", 0.0, 1.0);
  c.gait.max_extension_s = gait.nonNegative("max_extension_s");
  c.gait.first_swing_leg = gait.choice("first_swing_leg", kLegNames);

  auto& swing = root.child("swing");
  c.swing.lift_height_m = swing.nonNegative("lift_height_m");
  c.swing.touchdown_speed_mps = swing.nonNegative("touchdown_speed_mps");
  c.swing.replan_until_phase = swing.inRange("replan_until_phase", 0.0, 1.0);
  c.swing.late_replan_speed_mps = swing.nonNegative("late_replan_speed_mps");

  auto& fp = root.child("foot_placement");
  c.placement.k_v = fp.nonNegative("k_v");
  c.placement.k_p = fp.nonNegative("k_p");
  c.placement.max_offset_m = fp.positive("max_offset_m");

  auto& cmd = root.child("command");
  c.command.height_margin_m = cmd.nonNegative("height_margin_m");
  c.command.height_window_m = cmd.orderedPair("height_window_m");
  c.command.max_speed_mps = cmd.nonNegative("max_speed_mps");
  c.command.height_rate_mps = cmd.positive("height_rate_mps");
  auto& init = cmd.child("initial");
  c.command.initial_height_m = init.number("height_m");
  c.command.initial_speed_mps = init.number("speed_mps");
  c.command.initial_mode = init.choice("mode", kModeNames);

  return c;
}

}  // namespace

PlannerConfig loadPlannerConfig(const std::string& path) { return config::loadStrictFile(path, read); }

PlannerConfig parsePlannerConfig(const std::string& yaml_text, const std::string& origin) {
  return config::parseStrictString(yaml_text, origin, read);
}

bool parseLocomotionMode(const std::string& text, LocomotionMode* mode) {
  return config::parseName(kModeNames, text, mode);
}

const char* toString(LocomotionMode mode) { return config::nameOf(kModeNames, mode, "unknown"); }

}  // namespace mft::planner
