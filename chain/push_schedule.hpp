#pragma once
// The scenario's pushes as the simulator plays them: a push at a time is scheduled at the start; a push at a
// lift-off is armed only from its time on (the simulator triggers it at the next lift-off after it is
// scheduled, so scheduling it early would fire it at an earlier lift-off).
#include <utility>
#include <vector>

#include "chain/scenario.hpp"
#include "sim/simulator.hpp"

namespace mft::chain {

class ScenarioPushes {
 public:
  // Schedules the pushes at a time on `simulator` and keeps the lift-off ones for arm().
  ScenarioPushes(const std::vector<ScenarioPush>& pushes, sim::Simulator& simulator);
  // Before each step: schedules every lift-off push whose time has come. Never allocates.
  void arm(sim::Simulator& simulator);

 private:
  std::vector<std::pair<double, sim::ImpulseSpec>> waiting_;  // (armed from, spec)
};

}  // namespace mft::chain
