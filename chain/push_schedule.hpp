#pragma once
// The scenario's pushes as the simulator plays them: a push at a time is scheduled at the start; a push at a
// lift-off is armed only from its time on (the simulator triggers it at the next lift-off after it is
// scheduled, so scheduling it early would fire it at an earlier lift-off). A push at a gait phase is armed from
// its time on too, and fires in the first step that starts after that with its stance leg, once the planner's
// phase reaches it: what the planner says this tick (GaitPhase), so the push lands at a place in the gait.
#include <cstdint>
#include <utility>
#include <vector>

#include "chain/scenario.hpp"
#include "sim/simulator.hpp"

namespace mft::chain {

// The planner's gait state at this tick (its PlanOutput / Reference topic); known false: not available.
struct GaitPhase {
  bool known = false;
  std::uint64_t step_index = 0;  // lift-offs since the planner started
  double phase = 0.0;            // progress of the current swing in [0, 1]
  int stance_leg = -1;           // 0 right, 1 left, -1 double support
};

class ScenarioPushes {
 public:
  // Schedules the pushes at a time on `simulator` and keeps the lift-off and phase ones for arm().
  ScenarioPushes(const std::vector<ScenarioPush>& pushes, sim::Simulator& simulator);
  // Before each step: schedules every lift-off push whose time has come, and every phase push whose step and
  // phase `gait` has reached. Never allocates.
  void arm(sim::Simulator& simulator, const GaitPhase& gait = {});
  // Phase pushes not yet applied (a run on a stack without the planner's phase never fires them).
  bool phasePushesWaiting() const { return !phase_waiting_.empty(); }

 private:
  struct PhasePush {
    double from_s, phase;
    int stance_leg;
    bool armed = false;
    std::uint64_t armed_step = 0;  // the step in progress when armed: the push waits for a later one
    sim::ImpulseSpec spec;
  };
  bool due(PhasePush& p, double time_s, const GaitPhase& gait) const;

  std::vector<std::pair<double, sim::ImpulseSpec>> waiting_;  // (armed from, spec)
  std::vector<PhasePush> phase_waiting_;
};

}  // namespace mft::chain
