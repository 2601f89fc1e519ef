// Fuzz target: the strict YAML loaders of the configuration files (common/strict_yaml, config_schema). The
// input's first line names the loader (robot, wbc, planner, estimator, sim, terrain, mft_space), the rest is the
// file's text. A loader either returns a configuration or throws config::ConfigError naming the input.
#include "common/strict_yaml.hpp"
#include "estimator/estimator_config.hpp"
#include "fuzz/config_files.hpp"
#include "fuzz/fuzz_target.hpp"
#include "model/mft_polytope.hpp"
#include "planner/planner_config.hpp"
#include "sim/sim_options.hpp"
#include "sim/terrain.hpp"
#include "wbc/wbc_config.hpp"

namespace mft::fuzz {

namespace {

// Runs the loader named `kind` over `yaml`; false if there is no such loader.
bool load(const std::string& kind, const std::string& yaml, const std::string& origin) {
  if (kind == "robot") model::parseRobotDescription(yaml, origin);
  else if (kind == "wbc") wbc::validateWbcConfig(wbc::parseWbcConfig(yaml, origin), shippedRobot());
  else if (kind == "planner") planner::parsePlannerConfig(yaml, origin);
  else if (kind == "estimator") estimator::parseEstimatorConfig(yaml, origin);
  else if (kind == "sim") sim::parseSimOptions(yaml, origin);
  else if (kind == "terrain") sim::parseTerrain(yaml, origin);
  else if (kind == "mft_space") model::parseMftPolytope(yaml, origin, shippedRobot());
  else return false;
  return true;
}

}  // namespace

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  const std::string origin = "fuzz-input";
  const std::string text = bytesText(data, size);
  const std::size_t eol = text.find('\n');
  const std::string kind = text.substr(0, eol);
  const std::string yaml = eol == std::string::npos ? "" : text.substr(eol + 1);
  try {
    if (!load(kind, yaml, origin)) return refusedWith(origin + ": the first line names no loader", origin);
  } catch (const config::ConfigError& e) {
    return refusedWith(e.what(), origin);
  }
  return acceptedAs("a valid " + kind + " configuration");
}

}  // namespace mft::fuzz
