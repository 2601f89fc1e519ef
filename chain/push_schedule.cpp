#include "chain/push_schedule.hpp"

#include <algorithm>

namespace mft::chain {

ScenarioPushes::ScenarioPushes(const std::vector<ScenarioPush>& pushes, sim::Simulator& simulator) {
  for (const auto& p : pushes) {
    sim::ImpulseSpec spec;
    spec.impulse_Ns = {p.impulse_Ns, 0.0};
    spec.time_s = p.at_s;
    spec.trigger = p.at_liftoff_leg < 0 ? sim::ImpulseTrigger::AtTime : sim::ImpulseTrigger::AtLiftOff;
    spec.leg = std::max(0, p.at_liftoff_leg);
    if (spec.trigger == sim::ImpulseTrigger::AtTime) simulator.scheduleImpulse(spec);
    else waiting_.emplace_back(p.at_s, spec);
  }
}

void ScenarioPushes::arm(sim::Simulator& simulator) {
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    if (it->first <= simulator.time() + 1e-9) {
      simulator.scheduleImpulse(it->second);
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace mft::chain
