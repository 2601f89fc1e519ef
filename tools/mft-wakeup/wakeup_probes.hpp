#pragma once
// mft-wakeup's two probes (main.cpp reports them): timer lateness at 1 kHz and the one-way futex wake-up latency,
// each thread pinned to one CPU, SCHED_FIFO with `rt` where permitted.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mft::wakeup {

struct Stats {
  std::size_t count = 0;
  double p50 = 0, p99 = 0, max = 0, mean = 0;
};
Stats statsOf(std::vector<double> v);

// Lateness [us] of `samples` absolute deadlines `period_ns` apart on `cpu`; *fifo: whether SCHED_FIFO took.
std::vector<double> timerLateness(int cpu, int samples, std::int64_t period_ns, bool rt, bool* fifo);
// One-way wake-up latency [us] of a token handed `rounds` times between a thread on cpu_a and one on cpu_b.
std::vector<double> wakeupLatency(int cpu_a, int cpu_b, int rounds, bool rt);

}  // namespace mft::wakeup
