#pragma once
// The files of a recording before the first sample: never replace one silently, continue a crashed recorder's
// recording in the next piece, and store the effective configuration of every service in the rawlog's metadata.
#include <string>

#include "chain/scenario.hpp"
#include "model/robot_description.hpp"
#include "services/record/recorder.hpp"
#include "services/runtime/process.hpp"

namespace mft::services {

// After a crash the supervisor restarts the recorder with the same --output: the piece to continue in (0: a new
// recording). A restart is recognised by the sidecar of the output: still "recording", written by a recorder that
// is gone, under the same parent (the supervisor).
int firstPiece(const std::string& output);

// An existing --output (or its sidecar) is refused (exit 2) unless `overwrite`, which removes the old sidecar and
// pieces too, so that nothing of the old recording is read with the new one (`check_only`: removes nothing).
void refuseOrClearOldRecording(const std::string& output, bool overwrite, bool check_only, const CommandLine& cli);

// The files of `config_dir` every service read (with the profiles in force applied, so what is stored is what
// ran), the profiles verbatim, the scenario and its terrain: a recording can rebuild its controller
// (mft-replay --through-wbc). Exits 2 through `cli` on a missing or bad file.
void storeConfiguration(const std::string& config_dir, const std::string& scenario_file, const chain::Scenario& scenario,
                        const model::RobotDescription& robot, const CommandLine& cli, rawlog::Metadata* md);

}  // namespace mft::services
