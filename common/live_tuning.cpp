#include "common/live_tuning.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "common/config_schema.hpp"
#include "common/strict_yaml.hpp"
#include "common/text_split.hpp"

namespace mft::config {
namespace {

std::vector<std::string> splitKey(const std::string& dotted) { return splitOn(dotted, '.'); }

}  // namespace

const std::vector<TunableKey>& tunableKeys() {
  // Append only (the index is recorded). The WBC reads every one of these from its parameters at each tick,
  // the planner its swing, foot placement and height-rate parameters at each update (docs/guide/live-tuning.md).
  static const std::vector<TunableKey> keys = {
      {"wbc", "weights.base_z", 1},
      {"wbc", "weights.base_pitch", 1},
      {"wbc", "weights.swing_foot", 1},
      {"wbc", "weights.support_foot", 1},
      {"wbc", "weights.contact_force", 1},
      {"wbc", "weights.contact_force_rate", 1},
      {"wbc", "weights.slack", 1},
      {"wbc", "weights.qdd_regularization", 1},
      {"wbc", "weights.base_x", 1},
      {"wbc", "gains.base_z.kp", 1},
      {"wbc", "gains.base_z.kd", 1},
      {"wbc", "gains.base_pitch.kp", 1},
      {"wbc", "gains.base_pitch.kd", 1},
      {"wbc", "gains.swing_foot.kp", 2},
      {"wbc", "gains.swing_foot.kd", 2},
      {"wbc", "gains.support_foot.kp", 2},
      {"wbc", "gains.support_foot.kd", 2},
      {"wbc", "gains.base_x.kp", 1},
      {"wbc", "gains.base_x.kd", 1},
      {"planner", "swing.lift_height_m", 1},
      {"planner", "swing.touchdown_speed_mps", 1},
      {"planner", "swing.replan_until_phase", 1},
      {"planner", "swing.late_replan_speed_mps", 1},
      {"planner", "foot_placement.k_v", 1},
      {"planner", "foot_placement.k_p", 1},
      {"planner", "foot_placement.max_offset_m", 1},
      {"planner", "command.height_rate_mps", 1},
  };
  return keys;
}

int tunableIndex(const std::string& stem, const std::string& key) {
  const auto& keys = tunableKeys();
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (stem == keys[i].stem && key == keys[i].key) return static_cast<int>(i);
  return -1;
}

std::string describeTunable(const std::string& stem) {
  // "weights.*" for a section with several tunable keys (they are the whole section), else the key itself.
  std::vector<std::string> sections, items;
  for (const auto& k : tunableKeys()) {
    if (stem != k.stem) continue;
    const std::string key = k.key, section = key.substr(0, key.find('.'));
    int n = 0;
    for (const auto& o : tunableKeys())
      if (stem == o.stem && std::string(o.key).rfind(section + ".", 0) == 0) ++n;
    const std::string item = n > 1 ? section + ".*" : key;
    bool seen = false;
    for (const auto& i : items) seen = seen || i == item;
    if (!seen) items.push_back(item);
  }
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

std::string setKey(const std::string& yaml_text, const std::string& dotted_key, const std::string& value_yaml,
                   const std::string& origin) {
  YAML::Node root, value;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
  try {
    value = YAML::Load(value_yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": " + dotted_key + ": the value '" + value_yaml + "' is not YAML: " + e.what());
  }
  // A quoted value is text: keep it text in the emitted file (the emitter would write "5" as a plain 5).
  if (value.IsScalar() && value.Tag() == "!") value.SetTag("tag:yaml.org,2002:str");
  const auto parts = splitKey(dotted_key);
  if (parts.empty()) throw ConfigError(origin + ": an empty key");
  for (const auto& p : parts)
    if (p.empty()) throw ConfigError(origin + ": " + dotted_key + ": an empty part in the key");
  // yaml-cpp nodes are handles: walking with operator[] on copies edits the tree of `root`.
  std::vector<YAML::Node> path{root};
  std::string walked;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + parts[i];
    YAML::Node next = path.back()[parts[i]];
    if (next.IsDefined() && !next.IsMap())
      throw ConfigError(origin + ": " + walked + ": is a value, not a section (no key " + dotted_key + ")");
    path.push_back(next);
  }
  path.back()[parts.back()] = value;
  YAML::Emitter e;
  e << root;
  return std::string(e.c_str()) + "\n";
}

std::vector<double> numbersAt(const std::string& yaml_text, const std::string& dotted_key) {
  std::vector<double> out;
  try {
    YAML::Node n = YAML::Load(yaml_text);
    for (const auto& p : splitKey(dotted_key)) {
      if (!n.IsMap()) return {};
      n = n[p];
    }
    if (n.IsScalar()) out.push_back(n.as<double>());
    else if (n.IsSequence())
      for (const auto& x : n) out.push_back(x.as<double>());
  } catch (const YAML::Exception&) {
    return {};
  }
  return out;
}

std::string formatNumbers(const double* values, std::size_t count) {
  auto one = [](double v) {
    char buf[40];
    for (int digits = 6; digits <= 17; ++digits) {
      std::snprintf(buf, sizeof buf, "%.*g", digits, v);
      if (std::strtod(buf, nullptr) == v) break;
    }
    return std::string(buf);
  };
  if (count == 1) return one(values[0]);
  std::string out = "[";
  for (std::size_t i = 0; i < count; ++i) out += (i ? ", " : "") + one(values[i]);
  return out + "]";
}

namespace {
// The numbers of a plain YAML number or list of numbers; false for anything else (text, tags, mappings).
bool plainNumbers(const YAML::Node& n, std::vector<double>* out) {
  auto one = [out](const YAML::Node& x) {
    if (!x.IsScalar() || x.Tag() != "?") return false;
    char* end = nullptr;
    const std::string& s = x.Scalar();
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0') return false;
    out->push_back(v);
    return true;
  };
  if (n.IsScalar()) return one(n);
  if (!n.IsSequence() || n.size() == 0) return false;
  for (const auto& x : n)
    if (!one(x)) return false;
  return true;
}
}  // namespace

void checkLiveValue(const std::string& stem, const std::string& key, const std::string& value_yaml,
                    const std::string& origin) {
  const KeyRange* range = findKeyRange(stem, key);
  if (!range) return;
  YAML::Node value;
  try {
    value = YAML::Load(value_yaml);
  } catch (const YAML::Exception&) {
    throw ConfigError(origin + ": " + key + ": the value '" + value_yaml + "' is not YAML");
  }
  std::vector<double> numbers;
  if (!plainNumbers(value, &numbers))
    throw ConfigError(origin + ": " + key + ": expected a number or a list of numbers, got '" + value_yaml + "'");
  for (double v : numbers) {
    const std::string why = std::isfinite(v) ? rangeViolation(*range, v) : "must be finite";
    if (!why.empty()) throw ConfigError(origin + ": " + key + ": " + why);
  }
}

SetItem parseSetItem(const std::string& item, std::size_t max_chars) {
  const std::string origin = "--set '" + item + "'";
  const auto eq = item.find('='), dot = item.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
    throw ConfigError(origin + ": expected FILE.KEY=VALUE, e.g. wbc.weights.slack=1e5");
  SetItem s{item.substr(0, dot), item.substr(dot + 1, eq - dot - 1), item.substr(eq + 1)};
  if (s.file != "wbc" && s.file != "planner")
    throw ConfigError(origin + ": '" + s.file + "' is not a live-tunable file (wbc or planner)");
  if (s.value.empty()) throw ConfigError(origin + ": no value after '='");
  if (s.key.size() >= max_chars || s.value.size() >= max_chars)
    throw ConfigError(origin + ": key and value must be shorter than " + std::to_string(max_chars) + " characters each");
  return s;
}

void requireTunable(const std::string& stem, const std::string& key, const std::string& origin) {
  if (tunableIndex(stem, key) < 0)
    throw ConfigError(origin + ": " + key + ": not tunable while the stack runs (tunable: " + describeTunable(stem) + ")");
}

}  // namespace mft::config
