#pragma once
// Experiment scenarios (config/scenarios/*.yaml): what a stack runs, for how long, with which controller,
// on which terrain, and the operator commands and pushes to play at simulated times or events.
// One strict loader serves every service and the supervisor (`mft-sim --check-scenario FILE --json`).
#include <optional>
#include <string>
#include <vector>

#include "chain/push_recovery.hpp"
#include "planner/plan_output.hpp"

namespace mft::chain {

// The project's one locomotion mode is the planner's (planner/plan_output.hpp); the IDL's LOCOMOTION_* octets
// are converted at the DDS edge (mft-planner, the one reader of OperatorCommand).
using planner::LocomotionMode;

struct ScenarioCommand {
  double at_s = 0.0;
  LocomotionMode mode = LocomotionMode::Stand;
  double z_cmd_m = 0.0;
  double v_cmd_mps = 0.0;
};

struct ScenarioPush {
  double impulse_Ns = 0.0;  // sagittal, + forward
  double at_s = 0.0;        // applied at this time, or (with at_liftoff) armed from this time
  int at_liftoff_leg = -1;  // -1: at time; 0 right, 1 left: at that leg's next lift-off after at_s
  // At a gait phase instead (at_phase >= 0): at the planner's phase `at_phase` (0..1) of the first step that
  // starts after at_s with this stance leg (0 right, 1 left): the push lands at a place in the gait, not a time.
  double at_phase = -1.0;
  int stance_leg = -1;
};

struct Scenario {
  std::string source_file;
  std::string name;
  std::string description;
  double duration_s = 0.0;
  std::string controller;   // mft | sa | none
  std::string estimator;    // kalman | ground_truth
  std::string terrain;      // a file name in config/terrain/ without .yaml
  double initial_base_height_m = 0.0;
  // Distance between the feet at the start, right foot ahead, centred under the base [m]. Optional key
  // (default 0: both feet under the hip axis, a point support that suits stepping but not standing).
  double initial_stance_width_m = 0.0;
  std::vector<ScenarioCommand> commands;  // sorted by time, the first at 0
  std::vector<ScenarioPush> pushes;
  double fall_base_height_m = 0.0;        // the run counts as a fall below this base height
  double fall_pitch_rad = 0.0;            // ... or beyond this |pitch|
  // Optional section `recovery:` (every key optional, defaults in push_recovery.hpp): how a push run is judged.
  RecoveryCriteria recovery;
  std::vector<std::string> profiles;      // config/profiles/ names this scenario runs with (optional key)

  std::string toJson() const;
};

// Loads and validates a scenario file; throws mft::config::ConfigError naming the file and key.
Scenario loadScenario(const std::string& path);

// The profiles of a run: the scenario's, then `extra` (--profile values, comma lists allowed), each once, in
// that order. activateRunProfiles also loads them from `config_dir` and installs them for every configuration
// loader of this process (config::setActiveProfiles); it throws config::ConfigError on a bad profile.
std::vector<std::string> runProfiles(const Scenario& scenario, const std::vector<std::string>& extra);
std::vector<std::string> activateRunProfiles(const std::string& config_dir, const Scenario& scenario,
                                             const std::vector<std::string>& extra);
// A JSON list of names: ["a", "b"].
std::string profilesJson(const std::vector<std::string>& names);
Scenario parseScenario(const std::string& yaml_text, const std::string& origin);

}  // namespace mft::chain
