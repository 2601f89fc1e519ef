#include "chain/scenario.hpp"

#include <algorithm>
#include <cstdio>

#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "planner/planner_config.hpp"

namespace mft::chain {

using config::StrictNode;

namespace {

LocomotionMode parseMode(StrictNode& n, const std::string& key) {
  const std::string s = n.text(key);
  LocomotionMode mode;
  if (planner::parseLocomotionMode(s, &mode)) return mode;
  n.fail(key, "unknown mode '" + s + "' (expected stand, step_in_place or walk)");
}

std::string oneOf(StrictNode& n, const std::string& key, std::initializer_list<const char*> allowed) {
  const std::string s = n.text(key);
  std::string list;
  for (const char* a : allowed) {
    if (s == a) return s;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  n.fail(key, "unknown value '" + s + "' (expected one of " + list + ")");
}

Scenario read(StrictNode& root) {
  root.useSchema("scenario");  // every number it reads is checked against its range (config_schema.hpp)
  Scenario s;
  s.source_file = root.file();
  const int version = root.integer("schema_version");
  if (version != 1) root.fail("schema_version", "unsupported version " + std::to_string(version) + " (expected 1)");
  s.name = root.text("name");
  s.description = root.has("description") ? root.text("description") : "";
  s.duration_s = root.inRange("duration_s", 0.001, 3600.0);
  s.controller = oneOf(root, "controller", {"mft", "sa", "none"});
  s.estimator = oneOf(root, "estimator", {"kalman", "ground_truth"});
  s.terrain = root.text("terrain");
  if (s.terrain.empty() || s.terrain.find('/') != std::string::npos)
    root.fail("terrain", "expected a terrain name from config/terrain/ (no path)");
  s.initial_base_height_m = root.inRange("initial_base_height_m", 0.1, 1.0);
  s.initial_stance_width_m = root.has("initial_stance_width_m") ? root.inRange("initial_stance_width_m", 0.0, 0.4) : 0.0;
  auto& fall = root.child("fall");
  s.fall_base_height_m = fall.inRange("base_height_below_m", 0.0, 1.0);
  s.fall_pitch_rad = fall.inRange("pitch_beyond_rad", 0.0, 3.2);
  if (root.has("recovery")) {
    auto& r = root.child("recovery");
    RecoveryCriteria& c = s.recovery;
    if (r.has("rule") && !parseRecoveryRule(r.text("rule"), &c.rule))
      r.fail("rule", "unknown rule '" + r.text("rule") + "' (expected stepping or no_fall)");
    if (r.has("window_s")) c.window_s = r.inRange("window_s", 0.1, 10.0);
    if (r.has("max_speed_mps")) c.max_speed_mps = r.inRange("max_speed_mps", 0.0, 10.0);
    if (r.has("height_band_m")) c.height_band_m = r.inRange("height_band_m", 0.0, 1.0);
    if (r.has("max_pitch_rad")) c.max_pitch_rad = r.inRange("max_pitch_rad", 0.0, 3.2);
    if (r.has("min_touchdowns")) {
      c.min_touchdowns = r.integer("min_touchdowns");
      if (c.min_touchdowns < 0 || c.min_touchdowns > 100) r.fail("min_touchdowns", "expected 0..100");
    }
  }

  const std::size_t n_commands = root.listSize("commands");
  if (n_commands == 0) root.fail("commands", "at least one command (at_s: 0) is needed");
  for (std::size_t i = 0; i < n_commands; ++i) {
    auto& c = root.item("commands", i);
    ScenarioCommand cmd;
    cmd.at_s = c.inRange("at_s", 0.0, s.duration_s);
    cmd.mode = parseMode(c, "mode");
    cmd.z_cmd_m = c.inRange("z_cmd_m", 0.1, 1.0);
    cmd.v_cmd_mps = c.inRange("v_cmd_mps", -3.0, 3.0);
    if (!s.commands.empty() && cmd.at_s < s.commands.back().at_s) c.fail("at_s", "commands must be in time order");
    s.commands.push_back(cmd);
  }
  if (s.commands.front().at_s != 0.0) root.fail("commands", "the first command must be at_s: 0");

  if (root.has("profiles")) {
    s.profiles = config::splitProfileNames(root.texts("profiles"));
    for (const auto& name : s.profiles)
      if (name.find('/') != std::string::npos) root.fail("profiles", "expected names from config/profiles/ (no path)");
  }

  if (root.has("pushes")) {
    const std::size_t n_pushes = root.listSize("pushes");
    for (std::size_t i = 0; i < n_pushes; ++i) {
      auto& p = root.item("pushes", i);
      ScenarioPush push;
      push.impulse_Ns = p.inRange("impulse_Ns", -100.0, 100.0);
      push.at_s = p.inRange("at_s", 0.0, s.duration_s);
      if (p.has("at_liftoff")) {
        const std::string leg = oneOf(p, "at_liftoff", {"right", "left"});
        push.at_liftoff_leg = leg == "right" ? 0 : 1;
      }
      if (p.has("at_phase")) {
        if (p.has("at_liftoff")) p.fail("at_phase", "a push has one trigger: at_liftoff or at_phase, not both");
        push.at_phase = p.inRange("at_phase", 0.0, 0.999);
        push.stance_leg = oneOf(p, "stance", {"right", "left"}) == "right" ? 0 : 1;
      }
      s.pushes.push_back(push);
    }
  }
  root.finish();
  return s;
}

}  // namespace

Scenario loadScenario(const std::string& path) {
  auto root = StrictNode::loadFile(path);
  return read(root);
}

Scenario parseScenario(const std::string& yaml_text, const std::string& origin) {
  auto root = StrictNode::loadString(yaml_text, origin);
  return read(root);
}

std::vector<std::string> runProfiles(const Scenario& scenario, const std::vector<std::string>& extra) {
  std::vector<std::string> names;
  for (const auto& n : scenario.profiles)
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  for (const auto& n : config::splitProfileNames(extra))
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  return names;
}

std::vector<std::string> activateRunProfiles(const std::string& config_dir, const Scenario& scenario,
                                             const std::vector<std::string>& extra) {
  const auto names = runProfiles(scenario, extra);
  config::setActiveProfiles(config::ProfileSet::load(config_dir, names));
  return names;
}

std::string profilesJson(const std::vector<std::string>& names) {
  config::JsonWriter w;
  w.beginArray();
  for (const auto& name : names) w.value(name);
  return w.endArray().str();
}

std::string Scenario::toJson() const {
  constexpr int kDigits = 17;  // every value as loaded
  config::JsonWriter w;
  w.beginObject().field("name", name).field("file", source_file).field("duration_s", duration_s, kDigits);
  w.field("controller", controller).field("estimator", estimator).field("terrain", terrain);
  w.field("initial_base_height_m", initial_base_height_m, kDigits);
  w.field("initial_stance_width_m", initial_stance_width_m, kDigits);
  w.key("fall").beginObject().field("base_height_below_m", fall_base_height_m, kDigits);
  w.field("pitch_beyond_rad", fall_pitch_rad, kDigits).endObject();
  w.key("recovery").raw(recovery.toJson()).key("commands").beginArray();
  for (const auto& c : commands) {
    w.beginObject().field("at_s", c.at_s, kDigits).field("mode", toString(c.mode));
    w.field("z_cmd_m", c.z_cmd_m, kDigits).field("v_cmd_mps", c.v_cmd_mps, kDigits).endObject();
  }
  w.endArray().key("pushes").beginArray();
  for (const auto& p : pushes) {
    w.beginObject().field("impulse_Ns", p.impulse_Ns, kDigits).field("at_s", p.at_s, kDigits).key("at_liftoff");
    if (p.at_liftoff_leg < 0) w.null();
    else w.value(p.at_liftoff_leg == 0 ? "right" : "left");
    if (p.at_phase >= 0.0) w.field("at_phase", p.at_phase, kDigits).field("stance", p.stance_leg == 0 ? "right" : "left");
    w.endObject();
  }
  w.endArray().key("profiles").raw(profilesJson(profiles));
  return w.endObject().str();
}

}  // namespace mft::chain
