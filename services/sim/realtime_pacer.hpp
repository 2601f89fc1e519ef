#pragma once
// Realtime: the simulator's own 1 kHz wake-ups on absolute deadlines, and how late each came. A wake-up later
// than the whole watchdog timeout is a stall of the machine (a VM's vCPUs descheduled), which the controller
// suffered too: deadline misses then are the machine's, not the chain's. Per miss it keeps the simulator's own
// worst lateness over the 8 periods before (at most 64 misses: nothing allocates in the loop).
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "services/runtime/latency_stats.hpp"
#include "services/runtime/stall_probe.hpp"

namespace mft::services {

class RealtimePacer {
 public:
  using Clock = std::chrono::steady_clock;
  // spin: the last part of each period is spent polling the clock instead of asleep (0: sleep to the deadline).
  // A sleep ends late by the timer's and the scheduler's lateness; waking `spin` early and polling trades that
  // tail for a CPU busy that long per period.
  RealtimePacer(double period_s, std::int64_t watchdog_timeout_ns, Clock::duration spin = Clock::duration::zero())
      : period_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s))),
        watchdog_timeout_ns_(watchdog_timeout_ns),
        spin_(std::min(spin, period_)) {
    onset_late_ms_.reserve(64);
  }
  void start(Clock::time_point t0) { next_wakeup_ = t0; }
  Clock::time_point deadline() const { return next_wakeup_; }
  // Sleeps until the next period's deadline and books how late it woke up.
  void sleep() {
    next_wakeup_ += period_;
    std::this_thread::sleep_until(next_wakeup_ - spin_);
    while (Clock::now() < next_wakeup_) {
    }
    const double late_us = std::chrono::duration<double, std::micro>(Clock::now() - next_wakeup_).count();
    wakeup_late_us_.add(late_us);
    recent_late_us_[recent_index_++ % recent_late_us_.size()] = late_us;
    if (late_us * 1e3 > static_cast<double>(watchdog_timeout_ns_)) ++stalls_;
  }
  // The watchdog counted a miss in this period.
  void noteMiss() {
    if (onset_late_ms_.size() < 64)
      onset_late_ms_.push_back(*std::max_element(recent_late_us_.begin(), recent_late_us_.end()) * 1e-3);
  }
  // sim_wakeup_late_us, sim_stalls and damping_onset_sim_late_ms, as fields of the summary being written.
  void writeFields(config::JsonWriter& w) const {
    w.key("sim_wakeup_late_us").raw(wakeup_late_us_.json()).field("sim_stalls", stalls_);
    w.key("damping_onset_sim_late_ms").beginArray();
    for (const double late_ms : onset_late_ms_) w.fixed(late_ms, 3);
    w.endArray();
  }

 private:
  Clock::duration period_;
  std::int64_t watchdog_timeout_ns_;
  Clock::duration spin_;
  Clock::time_point next_wakeup_;
  LatencyStats wakeup_late_us_;
  std::array<double, 8> recent_late_us_{};
  std::size_t recent_index_ = 0;
  std::uint64_t stalls_ = 0;
  std::vector<double> onset_late_ms_;
};

// The CPU stall probe of `period_us` (null for 0): one SCHED_FIFO thread per CPU (stall_probe.hpp).
inline std::unique_ptr<StallProbe> makeStallProbe(long period_us) {
  if (period_us <= 0) return nullptr;
  StallProbe::Options o;
  o.period = std::chrono::microseconds(period_us);
  o.threshold = std::chrono::microseconds(std::max<long>(period_us, 1000));
  return std::make_unique<StallProbe>(o);
}

}  // namespace mft::services
