#include "planner/planner_tuning.hpp"

#include "model/config/live_tuning.hpp"
#include "model/config/strict_yaml.hpp"

namespace mft::planner {

PlannerOverride applyPlannerOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                                     const std::string& value_yaml) {
  PlannerOverride out;
  const std::string& where = origin;
  out.yaml_text = config::setKey(yaml_text, key, value_yaml, where);
  out.config = parsePlannerConfig(out.yaml_text, where);  // the strict loader: unknown keys, types, ranges
  if (config::tunableIndex("planner", key) < 0)
    throw config::ConfigError(where + ": " + key + ": not tunable while the stack runs (tunable: " +
                              config::describeTunable("planner") + ")");
  out.value = config::numbersAt(out.yaml_text, key);
  out.previous = config::numbersAt(yaml_text, key);
  return out;
}

}  // namespace mft::planner
