#include "wbc/wbc_tuning.hpp"

#include "model/config/live_tuning.hpp"
#include "model/config/strict_yaml.hpp"

namespace mft::wbc {

WbcOverride applyWbcOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                             const std::string& value_yaml, const model::RobotDescription& robot) {
  WbcOverride out;
  const std::string& where = origin;
  out.yaml_text = config::setKey(yaml_text, key, value_yaml, where);
  out.config = parseWbcConfig(out.yaml_text, where);  // the strict loader: unknown keys, types, ranges
  validateWbcConfig(out.config, robot);
  if (config::tunableIndex("wbc", key) < 0)
    throw config::ConfigError(where + ": " + key + ": not tunable while the stack runs (tunable: " +
                              config::describeTunable("wbc") + ")");
  out.value = config::numbersAt(out.yaml_text, key);
  out.previous = config::numbersAt(yaml_text, key);
  return out;
}

}  // namespace mft::wbc
