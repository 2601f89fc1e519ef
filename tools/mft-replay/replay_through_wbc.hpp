#pragma once
// mft-replay --through-wbc: the recorded RobotState and Reference through a fresh WholeBodyController built from
// the recorded configuration, its torques compared with the recorded JointCommands (a regression check).
#include "common/command_line.hpp"
#include "services/record/rawlog_reader.hpp"

namespace mft::replay {

constexpr int kExitMismatch = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitCorrupt = 4;

int throughWbc(rawlog::RawlogReader& reader, const config::CommandLine& cli);

}  // namespace mft::replay
