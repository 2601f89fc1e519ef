#include "wbc/wbc_tuning.hpp"

#include "common/live_tuning.hpp"

namespace mft::wbc {

WbcOverride applyWbcOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                             const std::string& value_yaml, const model::RobotDescription& robot) {
  return config::applyOverride<WbcConfig>("wbc", yaml_text, origin, key, value_yaml,
                                          [&](const std::string& text, const std::string& where) {
                                            WbcConfig c = parseWbcConfig(text, where);
                                            validateWbcConfig(c, robot);
                                            return c;
                                          });
}

}  // namespace mft::wbc
