#include "planner/planner_config.hpp"

#include "model/config/strict_yaml.hpp"

namespace mft::planner {
namespace {

using config::StrictNode;

PlannerConfig read(StrictNode& root) {
  PlannerConfig c;
  c.source_file = root.file();
  const int version = root.integer("schema_version");
  if (version != 1) root.fail("schema_version", "unsupported version " + std::to_string(version) + " (expected 1)");

  auto& gait = root.child("gait");
  c.gait.step_duration_s = gait.positive("step_duration_s");
  c.gait.double_support_s = gait.nonNegative("double_support_s");
  c.gait.min_touchdown_phase = gait.inRange("min_touchdown_phase", 0.0, 1.0);
  c.gait.max_extension_s = gait.nonNegative("max_extension_s");
  const std::string leg = gait.text("first_swing_leg");
  if (leg == "right") c.gait.first_swing_leg = model::kRightLeg;
  else if (leg == "left") c.gait.first_swing_leg = model::kLeftLeg;
  else gait.fail("first_swing_leg", "expected right or left, got '" + leg + "'");

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
  c.command.height_window_m = cmd.fixed<2>("height_window_m");
  if (!(c.command.height_window_m[0] < c.command.height_window_m[1]))
    cmd.fail("height_window_m", "expected [lower, upper] with lower < upper");
  c.command.max_speed_mps = cmd.nonNegative("max_speed_mps");
  c.command.height_rate_mps = cmd.positive("height_rate_mps");
  auto& init = cmd.child("initial");
  c.command.initial_height_m = init.number("height_m");
  c.command.initial_speed_mps = init.number("speed_mps");
  const std::string mode = init.text("mode");
  if (!parseLocomotionMode(mode, &c.command.initial_mode))
    init.fail("mode", "expected stand, step_in_place or walk, got '" + mode + "'");

  root.finish();
  return c;
}

}  // namespace

PlannerConfig loadPlannerConfig(const std::string& path) {
  auto root = StrictNode::loadFile(path);
  return read(root);
}

PlannerConfig parsePlannerConfig(const std::string& yaml_text, const std::string& origin) {
  auto root = StrictNode::loadString(yaml_text, origin);
  return read(root);
}

bool parseLocomotionMode(const std::string& text, LocomotionMode* mode) {
  if (text == "stand") *mode = LocomotionMode::Stand;
  else if (text == "step_in_place") *mode = LocomotionMode::StepInPlace;
  else if (text == "walk") *mode = LocomotionMode::Walk;
  else return false;
  return true;
}

const char* toString(LocomotionMode mode) {
  switch (mode) {
    case LocomotionMode::Stand: return "stand";
    case LocomotionMode::StepInPlace: return "step_in_place";
    case LocomotionMode::Walk: return "walk";
  }
  return "unknown";
}

}  // namespace mft::planner
