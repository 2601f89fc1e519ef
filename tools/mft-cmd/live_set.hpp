#pragma once
// mft-cmd --set: live tuning (docs/guide/live-tuning.md). One ConfigChange per FILE.KEY=VALUE, written in order (each
// acknowledged before the next: the command writer keeps one sample), then every verdict awaited. The exit
// status is the worst of the changes.
#include "common/command_line.hpp"

namespace mft::cmd {

int runSet(const config::CommandLine& cli);

}  // namespace mft::cmd
