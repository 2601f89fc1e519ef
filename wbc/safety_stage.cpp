#include "wbc/safety_stage.hpp"

#include <algorithm>
#include <cmath>

#include "common/enum_names.hpp"

namespace mft::wbc {

constexpr config::EnumName<SafetyMode> kSafetyModeNames[] = {
    {SafetyMode::Normal, "normal"}, {SafetyMode::Holding, "holding"}, {SafetyMode::Damping, "damping"}};
constexpr config::EnumName<SafetyEvent> kSafetyEventNames[] = {{SafetyEvent::None, "none"},
                                                               {SafetyEvent::NonFiniteInput, "non-finite input"},
                                                               {SafetyEvent::ModelFailure, "model failure"},
                                                               {SafetyEvent::SolverFailure, "solver failure"},
                                                               {SafetyEvent::NonFiniteOutput, "non-finite output"},
                                                               {SafetyEvent::Exception, "exception"}};

const char* toString(SafetyMode m) { return config::nameOf(kSafetyModeNames, m); }

const char* toString(SafetyEvent e) { return config::nameOf(kSafetyEventNames, e); }

SafetyStage::SafetyStage(int hold_ticks, double damping_gain, const model::VectorA& tau_max, bool latch_damping)
    : hold_ticks_(hold_ticks), damping_gain_(damping_gain), tau_max_(tau_max), latch_damping_(latch_damping) {}

model::ActuatorCommand SafetyStage::accept(const model::ActuatorCommand& good, const model::VectorQ& qd) {
  if (mode_ == SafetyMode::Damping && latch_damping_) {
    ++counters_.damping_ticks;
    return damping(good.tick, qd);
  }
  mode_ = SafetyMode::Normal;
  consecutive_failures_ = 0;
  last_good_ = good;
  have_good_ = true;
  return good;
}

model::ActuatorCommand SafetyStage::reject(SafetyEvent cause, std::uint64_t tick, const model::VectorQ& qd) {
  ++counters_.events;
  switch (cause) {
    case SafetyEvent::NonFiniteInput: ++counters_.nonfinite_input; break;
    case SafetyEvent::ModelFailure: ++counters_.model_failure; break;
    case SafetyEvent::SolverFailure: ++counters_.solver_failure; break;
    case SafetyEvent::NonFiniteOutput: ++counters_.nonfinite_output; break;
    case SafetyEvent::Exception: ++counters_.exception; break;
    case SafetyEvent::None: break;
  }
  last_event_ = cause;
  ++consecutive_failures_;
  if (mode_ != SafetyMode::Damping && have_good_ && consecutive_failures_ <= hold_ticks_) {
    mode_ = SafetyMode::Holding;
    ++counters_.hold_ticks;
    model::ActuatorCommand held = last_good_;
    held.tick = tick;
    return held;
  }
  if (mode_ != SafetyMode::Damping) ++counters_.damping_entries;
  mode_ = SafetyMode::Damping;
  ++counters_.damping_ticks;
  return damping(tick, qd);
}

model::ActuatorCommand SafetyStage::damping(std::uint64_t tick, const model::VectorQ& qd) {
  model::ActuatorCommand cmd;
  cmd.tick = tick;
  cmd.mode = model::CommandMode::Damping;
  for (int i = 0; i < model::kNa; ++i) {
    const double v = qd[model::kActuatedIndex[i]];
    const double t = std::isfinite(v) ? -damping_gain_ * v : 0.0;
    cmd.tau[i] = std::max(-tau_max_[i], std::min(tau_max_[i], t));
  }
  return cmd;
}

void SafetyStage::reset() {
  mode_ = SafetyMode::Normal;
  consecutive_failures_ = 0;
  have_good_ = false;
  last_event_ = SafetyEvent::None;
}

}  // namespace mft::wbc
