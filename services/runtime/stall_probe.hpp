#pragma once
// Tells the machine's stalls from the control chain's: one thread per CPU of the process, pinned to it at
// the highest SCHED_FIFO priority it may take, wakes every `period` and records every wake-up later than
// `threshold` as a stall [scheduled, woke). Nothing of ours can delay such a thread by milliseconds on an
// idle machine; a hypervisor descheduling the vCPU can (this VM: 3-30 ms bursts). The simulator asks, for
// each deadline miss, how long any CPU was stalled while the tick waited. No allocation after start.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace mft::services {

class StallProbe {
 public:
  struct Options {
    std::chrono::microseconds period{1000};
    std::chrono::microseconds threshold{1000};
    std::size_t capacity = 1024;  // stalls kept (the oldest go first)
  };
  explicit StallProbe(const Options& options);
  ~StallProbe();
  StallProbe(const StallProbe&) = delete;
  StallProbe& operator=(const StallProbe&) = delete;

  // Time [ns] within [t0_ns, t1_ns] (steady_clock) during which at least one CPU was stalled.
  std::int64_t stalledWithinNs(std::int64_t t0_ns, std::int64_t t1_ns) const;
  // How long some CPU stood still while a tick waited for its command until `deadline_ns` (published
  // `timeout_ns` before it). The window is widened by one probe period on each side: a stall is recorded
  // from the first probe wake-up it delayed, up to one period after it began.
  std::int64_t stalledWhileWaitingNs(std::int64_t deadline_ns, std::int64_t timeout_ns) const;
  // A miss is the machine's when some CPU stood still for at least half the timeout while the tick waited:
  // the chain's p99 is under 0.5 ms, so missing 3 ms takes a stall of that order (or a chain too slow on
  // every tick, which the damping totals show).
  static bool explainsMiss(std::int64_t stalled_ns, std::int64_t timeout_ns) { return stalled_ns * 2 >= timeout_ns; }
  std::uint64_t stalls() const;
  // The stalls kept [from, to) ns (steady_clock, which every process shares): the supervisor judges the other
  // services' deadline misses against them.
  std::vector<std::pair<std::int64_t, std::int64_t>> stallWindows() const;
  double maxStallMs() const;
  double totalStallMs() const;
  int cpus() const { return probing_.load(); }  // the CPUs a probe thread runs on
  bool realtimePriority() const { return realtime_priority_; }

  // For tests: record a stall as a probe thread would.
  void recordStall(std::int64_t from_ns, std::int64_t to_ns);

 private:
  void run(int cpu);

  Options options_;
  mutable std::mutex mutex_;
  std::vector<std::pair<std::int64_t, std::int64_t>> ring_;  // preallocated, `capacity` entries
  std::size_t next_ = 0, count_ = 0;
  std::uint64_t stalls_ = 0;
  std::int64_t max_stall_ns_ = 0, total_stall_ns_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> probing_{0};  // probe threads pinned to their CPU
  std::atomic<int> started_{0};  // probe threads that tried their CPU
  bool realtime_priority_ = true;
  std::vector<std::thread> threads_;
};

}  // namespace mft::services
