#include "services/sim/check_scenario.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "chain/scenario_limits.hpp"
#include "chain/sim_node.hpp"
#include "common/install_layout.hpp"
#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"
#include "services/runtime/process.hpp"

namespace mft::services {

bool isCheckScenario(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--check-scenario" || std::string(argv[i]).rfind("--check-scenario=", 0) == 0) return true;
  return false;
}

int checkScenario(int argc, char** argv) {
  CommandLine cli("mft-sim --check-scenario", "Validate a scenario file (and its terrain) and exit.");
  cli.option("check-scenario", "the scenario file", "", true);
  cli.option("config-dir", "configuration folder", config::configDirFor(MFT_CONFIG_DIR));
  cli.option("profile", "configuration profile, after the scenario's (repeatable): checked against every "
             "configuration file");
  cli.flag("json", "print the scenario as JSON (its profiles: the scenario's, then --profile)");
  cli.parse(argc, argv);
  try {
    auto scenario = chain::loadScenario(cli.get("check-scenario"));
    scenario.profiles = chain::activateRunProfiles(cli.get("config-dir"), scenario, cli.getAll("profile"));
    config::activeProfiles().check(cli.get("config-dir"));
    const auto robot = model::loadRobotDescription(cli.get("config-dir") + "/robot.yaml");
    const auto terrain = sim::loadTerrain(cli.get("config-dir") + "/terrain/" + scenario.terrain + ".yaml");
    const auto options = sim::loadSimOptions(cli.get("config-dir") + "/sim.yaml");
    chain::checkScenarioLimits(scenario, robot, cli.get("config-dir") + "/planner.yaml");
    // And the initial pose exactly as mft-sim will build it, on this terrain.
    try {
      sim::Simulator simulator(robot, options, terrain);
      simulator.standingConfiguration(chain::initialPose(scenario));
    } catch (const std::invalid_argument& e) {
      throw config::ConfigError(scenario.source_file + ": initial_base_height_m: the initial pose cannot be built on terrain '" +
                                scenario.terrain + "': " + e.what());
    }
    if (cli.isSet("json")) std::printf("%s\n", scenario.toJson().c_str());
    else std::printf("%s: scenario '%s' is valid (%.3f s, controller %s)\n", scenario.source_file.c_str(),
                     scenario.name.c_str(), scenario.duration_s, scenario.controller.c_str());
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}

}  // namespace mft::services
