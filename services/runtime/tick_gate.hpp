#pragma once
// Which ticks a service answers (docs/results/faults.md). Each service answers tick k once and ignores older ticks;
// without a guard a single sample with a tick far ahead (a corrupted or injected one) made it ignore every
// real tick after it for good, and a restarted simulator (its clock back at 0) was ignored for as long as
// the old clock had run. The gate accepts a jump of more than `max_jump` ticks ahead, or a fall back by more
// than `max_jump` (a new clock), only when the next sample continues it: one stray sample is refused, a real
// new timeline costs one tick. A consistent forged timeline cannot be told from a real one here: DDS
// Security's access control keeps such writers out (docs/guide/security.md). Pure logic, unit-tested
// (tests/faults/test_input_guards.cpp).
#include <cstdint>

namespace mft::services {

class TickGate {
 public:
  enum class Decision { Answer, Repeat, Stale, Refused, NewClock };

  explicit TickGate(std::uint64_t max_jump = 200) : max_jump_(max_jump) {}

  // Call for each input sample; Answer/NewClock: process it (then call answered()), Repeat: the tick already
  // answered (send the cached answer where the mode wants it), Stale/Refused: ignore it.
  Decision check(std::uint64_t tick) {
    if (!have_) return Decision::Answer;
    if (tick == last_) return Decision::Repeat;
    const bool ahead = tick > last_;
    const std::uint64_t distance = ahead ? tick - last_ : last_ - tick;
    if (ahead && distance <= max_jump_) {
      has_candidate_ = false;
      return Decision::Answer;
    }
    if (!ahead && distance <= max_jump_) return Decision::Stale;
    // A far jump, ahead or back: only when the previous refused sample led straight to this one.
    if (has_candidate_ && (tick == candidate_ + 1 || tick == candidate_)) {
      has_candidate_ = false;
      ++new_clocks_;
      last_ = tick;  // the new timeline is adopted now, answered or not
      return ahead ? Decision::Answer : Decision::NewClock;
    }
    candidate_ = tick;
    has_candidate_ = true;
    ++refused_;
    return Decision::Refused;
  }
  void answered(std::uint64_t tick) {
    last_ = tick;
    have_ = true;
  }
  // After a NewClock the answered tick may be lower than before.
  std::uint64_t last() const { return last_; }
  bool any() const { return have_; }
  std::uint64_t refused() const { return refused_; }
  std::uint64_t newClocks() const { return new_clocks_; }

 private:
  std::uint64_t max_jump_;
  bool have_ = false, has_candidate_ = false;
  std::uint64_t last_ = 0, candidate_ = 0, refused_ = 0, new_clocks_ = 0;
};

}  // namespace mft::services
