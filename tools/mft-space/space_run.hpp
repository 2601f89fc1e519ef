#pragma once
// The offline pipeline's command-line side: its options to settings, the polytope file it writes, its summary.
// The pipeline itself (grid both spaces, fit, measure, assemble the polytope) is model/mft_space_fit.hpp.
#include <string>

#include "cli_args.hpp"
#include "model/mft_space_fit.hpp"

namespace mft::tools {

// Options shared by every command that grids: thresholds, RACI form, resolutions, fit settings.
extern const char* const kSpaceOptions[];
model::MftSpaceSettings settingsFromArgs(const CliArgs& a, const model::RobotDescription& robot);
// The criteria part only (for `index`).
model::MftCriteria criteriaFromArgs(const CliArgs& a, const model::RobotDescription& robot);

// Writes the YAML; throws std::runtime_error if the file cannot be written.
void writePolytopeFile(const std::string& path, const model::MftSpaceResult& r, const model::RobotDescription& robot);

std::string summaryJson(const model::MftSpaceResult& r);
std::string summaryText(const model::MftSpaceResult& r);

}  // namespace mft::tools
