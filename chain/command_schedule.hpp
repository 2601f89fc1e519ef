#pragma once
// The scenario's operator commands on the simulator's clock: which are due at a tick (the planner applies a
// command from the first tick whose time reaches at_s) and the height command in force at a time (the run
// monitor's height error). One rule for mft-planner, mft-sim and the in-process loop.
#include <cstddef>
#include <vector>

#include "chain/scenario.hpp"
#include "planner/operator_command.hpp"

namespace mft::chain {

inline planner::OperatorCommand toOperatorCommand(const ScenarioCommand& c) {
  return {c.z_cmd_m, c.v_cmd_mps, c.mode};
}

// The height command in force at time `t` (the scenario's first command is at 0).
double commandedHeight(const Scenario& scenario, double t);

class CommandSchedule {
 public:
  explicit CommandSchedule(const std::vector<ScenarioCommand>& commands) : commands_(&commands) {}
  // Calls apply(const ScenarioCommand&) for each command not yet given that is due at `time_s`.
  template <class Apply>
  void applyDue(double time_s, Apply&& apply) {
    while (next_ < commands_->size() && (*commands_)[next_].at_s <= time_s + 1e-9) apply((*commands_)[next_++]);
  }
  // A new clock (a restarted simulator): the commands play again from the first.
  void restart() { next_ = 0; }

 private:
  const std::vector<ScenarioCommand>* commands_;
  std::size_t next_ = 0;
};

}  // namespace mft::chain
