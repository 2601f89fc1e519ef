#pragma once
// The last stage before the actuators. A good command passes; on a failure (non-finite input, solver
// failure, non-finite result, exception) the last good command is held for hold_ticks ticks, then joint
// damping is commanded (CommandMode::Damping, tau = -k qd_a). Every failing tick is counted by cause.
#include <cstdint>

#include "model/robot_io.hpp"

namespace mft::wbc {

enum class SafetyMode { Normal, Holding, Damping };
enum class SafetyEvent { None, NonFiniteInput, ModelFailure, SolverFailure, NonFiniteOutput, Exception };
const char* toString(SafetyMode m);
const char* toString(SafetyEvent e);

struct SafetyCounters {
  std::uint64_t events = 0;            // failing ticks, all causes
  std::uint64_t nonfinite_input = 0;   // NaN / inf in the state or the reference
  std::uint64_t model_failure = 0;     // non-finite dynamics (e.g. a singular closure projection)
  std::uint64_t solver_failure = 0;    // QP status other than Optimal
  std::uint64_t nonfinite_output = 0;  // non-finite QP solution or torques
  std::uint64_t exception = 0;         // an exception escaped the tick
  std::uint64_t hold_ticks = 0;        // ticks that held the last good command
  std::uint64_t damping_ticks = 0;     // ticks that commanded damping
  std::uint64_t damping_entries = 0;   // transitions into damping
};

class SafetyStage {
 public:
  SafetyStage(int hold_ticks, double damping_gain, const model::VectorA& tau_max, bool latch_damping);

  // A good command for this tick: passed on (and remembered), unless damping is latched.
  model::ActuatorCommand accept(const model::ActuatorCommand& good, const model::VectorQ& qd);
  // This tick failed: hold the last good command or damp. qd may be non-finite (then zero damping torque).
  model::ActuatorCommand reject(SafetyEvent cause, std::uint64_t tick, const model::VectorQ& qd);

  SafetyMode mode() const { return mode_; }
  SafetyEvent lastEvent() const { return last_event_; }
  int consecutiveFailures() const { return consecutive_failures_; }
  const SafetyCounters& counters() const { return counters_; }
  // Leaves a latched damping state and forgets the last good command (counters are kept).
  void reset();

 private:
  model::ActuatorCommand damping(std::uint64_t tick, const model::VectorQ& qd);

  int hold_ticks_;
  double damping_gain_;
  model::VectorA tau_max_;
  bool latch_damping_;
  SafetyMode mode_ = SafetyMode::Normal;
  SafetyEvent last_event_ = SafetyEvent::None;
  int consecutive_failures_ = 0;
  bool have_good_ = false;
  model::ActuatorCommand last_good_;
  SafetyCounters counters_;
};

}  // namespace mft::wbc
