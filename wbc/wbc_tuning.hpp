#pragma once
// Live tuning of the WBC (docs/guide/live-tuning.md): a `weights.*` or `gains.*` key of config/wbc.yaml changed while
// the controller runs. A change is judged off the control loop by config/wbc.yaml's own strict loader
// (applyWbcOverride) and swapped in at a tick boundary by WholeBodyController::setTuning, which copies a few
// doubles and allocates nothing.
#include <string>
#include <vector>

#include "model/robot_description.hpp"
#include "common/live_tuning.hpp"
#include "wbc/wbc_config.hpp"

namespace mft::wbc {

// What a live change may touch: the cost weights (15) and the PD gains (17).
struct WbcTuning {
  WbcWeights weights;
  WbcGains gains;
};
inline WbcTuning tuningOf(const WbcConfig& c) { return {c.weights, c.gains}; }

using WbcOverride = config::ConfigOverride<WbcConfig>;

// Sets `key` (a dotted key of config/wbc.yaml, e.g. "weights.slack") to `value_yaml` in `yaml_text` (the
// configuration in force, named `origin` in messages) and loads the result with parseWbcConfig and
// validateWbcConfig. Throws config::ConfigError with the loader's message for an unknown key or an invalid
// value, and for a valid key that is not tunable live (config/live_tuning.hpp).
WbcOverride applyWbcOverride(const std::string& yaml_text, const std::string& origin, const std::string& key,
                             const std::string& value_yaml, const model::RobotDescription& robot);

}  // namespace mft::wbc
