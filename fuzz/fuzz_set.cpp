// Fuzz target: one `mft-cmd --set FILE.KEY=VALUE` item (a command-line argument: the input up to its first NUL)
// through both ends: mft-cmd's parser and range check before sending, then the answering service's judge (the
// file's strict loader over the shipped wbc.yaml or planner.yaml with the change set), as mft-wbc and mft-planner
// judge a ConfigChange. Each end either takes the change or throws config::ConfigError naming it.
#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "fuzz/config_files.hpp"
#include "fuzz/fuzz_target.hpp"
#include "planner/planner_tuning.hpp"
#include "wbc/wbc_tuning.hpp"

namespace mft::fuzz {

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  const std::string bytes = bytesText(data, size);
  const std::string item = bytes.substr(0, bytes.find('\0'));
  const std::string origin = "--set '" + item + "'";
  config::SetItem s;
  try {
    s = config::parseSetItem(item, 64);
    config::checkLiveValue(s.file, s.key, s.value, origin);
  } catch (const config::ConfigError& e) {
    return refusedWith(e.what(), origin);
  }
  static const std::string wbc_text = configFile("wbc.yaml"), planner_text = configFile("planner.yaml");
  const std::string service_origin = s.file + ".yaml (live change)";
  std::vector<double> value;
  try {
    if (s.file == "wbc")
      value = wbc::applyWbcOverride(wbc_text, service_origin, s.key, s.value, shippedRobot()).value;
    else
      value = planner::applyPlannerOverride(planner_text, service_origin, s.key, s.value).value;
  } catch (const config::ConfigError& e) {
    return refusedWith(e.what(), service_origin);
  }
  return acceptedAs(s.file + "." + s.key + " = " + config::formatNumbers(value.data(), value.size()));
}

}  // namespace mft::fuzz
