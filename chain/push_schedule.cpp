#include "chain/push_schedule.hpp"

#include <algorithm>

namespace mft::chain {

ScenarioPushes::ScenarioPushes(const std::vector<ScenarioPush>& pushes, sim::Simulator& simulator) {
  phase_waiting_.reserve(pushes.size());
  for (const auto& p : pushes) {
    sim::ImpulseSpec spec;
    spec.impulse_Ns = {p.impulse_Ns, 0.0};
    spec.time_s = p.at_s;
    if (p.at_phase >= 0.0) {  // fired by arm() as a push at the time the phase is reached
      spec.trigger = sim::ImpulseTrigger::AtTime;
      phase_waiting_.push_back({p.at_s, p.at_phase, p.stance_leg, false, 0, spec});
      continue;
    }
    spec.trigger = p.at_liftoff_leg < 0 ? sim::ImpulseTrigger::AtTime : sim::ImpulseTrigger::AtLiftOff;
    spec.leg = std::max(0, p.at_liftoff_leg);
    if (spec.trigger == sim::ImpulseTrigger::AtTime) simulator.scheduleImpulse(spec);
    else waiting_.emplace_back(p.at_s, spec);
  }
}

bool ScenarioPushes::due(PhasePush& p, double time_s, const GaitPhase& gait) const {
  if (!gait.known || time_s + 1e-9 < p.from_s) return false;
  if (!p.armed) {  // the step in progress at the arming time is not "the next step"
    p.armed = true;
    p.armed_step = gait.step_index;
    return false;
  }
  return gait.step_index > p.armed_step && gait.stance_leg == p.stance_leg && gait.phase + 1e-12 >= p.phase;
}

void ScenarioPushes::arm(sim::Simulator& simulator, const GaitPhase& gait) {
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    if (it->first <= simulator.time() + 1e-9) {
      simulator.scheduleImpulse(it->second);
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto it = phase_waiting_.begin(); it != phase_waiting_.end();) {
    if (due(*it, simulator.time(), gait)) {
      it->spec.time_s = simulator.time();  // applied by this step
      simulator.scheduleImpulse(it->spec);
      it = phase_waiting_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace mft::chain
