#include "planner/planner_tuning.hpp"

#include "common/live_tuning.hpp"

namespace mft::planner {

PlannerOverride applyPlannerOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                                     const std::string& value_yaml) {
  return config::applyOverride<PlannerConfig>("planner", yaml_text, origin, key, value_yaml, parsePlannerConfig);
}

}  // namespace mft::planner
