#pragma once
// mft-cmd --mode / --push: one OperatorCommand (answered by the planner) or Disturbance (by the simulator),
// written once a reader of the stack matched, then its verdicts awaited: rejected, or scheduled then applied.
#include "common/command_line.hpp"

namespace mft::cmd {

int runCommand(const config::CommandLine& cli);

}  // namespace mft::cmd
