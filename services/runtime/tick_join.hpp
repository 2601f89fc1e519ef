#pragma once
// The part every chain service repeats around its node (docs/results/faults.md): pair the inputs of tick k, refuse what
// must not reach the node, answer each tick once and a repeated tick with the cached answer. Inputs that are not
// finite or implausible are refused and counted (msg_guard.hpp), the service keeps its last good input; the
// tick-naming input passes the TickGate (a stray far tick is refused, a restarted simulator is followed). Pure
// logic, no DDS; the caller holds its mutex around every call.
#include <cstdint>
#include <cstdio>
#include <string>

#include "common/json_writer.hpp"
#include "services/runtime/tick_gate.hpp"

namespace mft::services {

class TickJoin {
 public:
  enum class Action { Compute, Resend, Wait };

  explicit TickJoin(const char* service) : service_(service) {}

  // Counts an input that failed validation (the first one is logged). Returns `valid`.
  bool accept(bool valid, const char* topic, std::uint64_t tick) {
    if (!valid && refused_inputs_++ == 0)
      std::printf("%s: refused a non-finite or implausible %s (tick %llu)\n", service_, topic,
                  static_cast<unsigned long long>(tick));
    return valid;
  }
  // The tick-naming input of `tick` arrived (valid). False: ignore it (a stray tick). `new_clock` is set when the
  // simulator restarted: the caller restarts its node, and the tick is answered afresh.
  bool admit(std::uint64_t tick, bool* new_clock) {
    const auto decision = gate_.check(tick);
    *new_clock = decision == TickGate::Decision::NewClock;
    if (decision == TickGate::Decision::Refused) return false;
    if (*new_clock) {
      std::printf("%s: the simulator's clock restarted (tick %llu after %llu)\n", service_,
                  static_cast<unsigned long long>(tick), static_cast<unsigned long long>(last_));
      answered_ = false;
    }
    return true;
  }
  // accept() and admit() of the tick-naming input in one: false when it is refused or a stray tick; `new_clock`
  // (if given) is set when the simulator restarted.
  bool acceptTick(bool valid, const char* topic, std::uint64_t tick, bool* new_clock = nullptr) {
    bool restarted = false;
    if (!accept(valid, topic, tick) || !admit(tick, &restarted)) return false;
    if (new_clock) *new_clock = restarted;
    return true;
  }
  // What to do for `tick` with the inputs now held: `paired` says whether every input it needs is there;
  // `repeat_answer`: a repeated tick gets the cached answer again (only when its tick-naming input came again,
  // so that a second input topic of the same tick does not double the chain's traffic).
  Action decide(std::uint64_t tick, bool paired, bool repeat_answer) const {
    if (answered_ && tick == last_) return repeat_answer ? Action::Resend : Action::Wait;
    if (answered_ && tick < last_) return Action::Wait;
    return paired ? Action::Compute : Action::Wait;
  }
  void answered(std::uint64_t tick) {
    last_ = tick;
    answered_ = true;
    gate_.answered(tick);
    ++ticks_;
  }

  std::uint64_t ticks() const { return ticks_; }
  std::uint64_t lastTick() const { return last_; }
  // refused_inputs, refused_ticks and new_clocks, as fields of the summary object being written.
  void writeCounts(config::JsonWriter& w) const {
    w.field("refused_inputs", refused_inputs_).field("refused_ticks", gate_.refused()).field("new_clocks", gate_.newClocks());
  }

 private:
  const char* service_;
  TickGate gate_;
  bool answered_ = false;
  std::uint64_t last_ = 0, ticks_ = 0, refused_inputs_ = 0;
};

}  // namespace mft::services
