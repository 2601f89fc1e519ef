#pragma once
// mft-closedloop's steps (main.cpp reads as their sequence): its options, the scenario they make (a file with
// overrides, or stand-then-step), what is written per tick (CSV trace, trajectory, the QP dump window) and the
// text summary.
#include <cstdint>
#include <fstream>
#include <string>

#include "chain/closed_loop.hpp"
#include "common/command_line.hpp"

namespace mft::closedloop {

void declareOptions(config::CommandLine& cli);

// The scenario the options describe, its configurations loaded and its limits checked as mft-sim
// --check-scenario does; a bad option or file is a one-line usage error.
chain::Scenario scenarioFromOptions(const config::CommandLine& cli, Configs* configs);

// --csv, --trajectory and --dump-qp: opened (and refused) before the run, fed each tick.
class TickOutputs {
 public:
  TickOutputs(const config::CommandLine& cli, const Configs& configs);
  void onTick(const ClosedLoop& loop);
  // After the run: a dump error or a run that ended before the dump window did is a usage error.
  void finish(const config::CommandLine& cli) const;

 private:
  void dumpQp(const wbc::WholeBodyController& c);
  std::ofstream csv_, trajectory_;
  long every_ = 1, n_ = 0;
  bool dump_ = false;
  std::string dump_dir_, dump_name_, dump_error_;
  std::uint64_t dump_first_ = 0, dump_end_ = 0, dumped_ = 0;
};

void printTextSummary(const chain::Scenario& scenario, const RunSummary& s, const ClosedLoop& loop, double stats_from_s);

}  // namespace mft::closedloop
