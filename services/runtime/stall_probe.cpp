#include "services/runtime/stall_probe.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>

namespace mft::services {

namespace {
std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

// Every online CPU, not only this process's: a realtime stack pins its chain (and so the simulator) to one core,
// and a stall of the other core still delays the services placed there. A CPU this thread may not run on (a
// cpuset) is left out: its thread ends at once and is not counted.
StallProbe::StallProbe(const Options& options) : options_(options), ring_(std::max<std::size_t>(options.capacity, 1)) {
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  for (int cpu = 0; cpu < std::min<long>(online, CPU_SETSIZE); ++cpu) threads_.emplace_back([this, cpu] { run(cpu); });
  // cpus() is final once every thread has tried its CPU (a start-up matter of microseconds; bounded anyway).
  for (int i = 0; i < 20000 && started_.load() < static_cast<int>(threads_.size()); ++i)
    std::this_thread::sleep_for(std::chrono::microseconds(100));
}

StallProbe::~StallProbe() {
  stop_ = true;
  for (auto& t : threads_) t.join();
}

void StallProbe::run(int cpu) {
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  const bool pinned = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
  if (pinned) ++probing_;
  ++started_;
  if (!pinned) return;
  sched_param param{};
  param.sched_priority = sched_get_priority_max(SCHED_FIFO);
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) != 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    realtime_priority_ = false;  // still useful: a normal thread on an idle machine wakes on time too
  }
  const std::int64_t period_ns = options_.period.count() * 1000;
  const std::int64_t threshold_ns = options_.threshold.count() * 1000;
  std::int64_t next = steadyNs();
  while (!stop_) {
    next += period_ns;
    timespec ts{static_cast<time_t>(next / 1000000000LL), static_cast<long>(next % 1000000000LL)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);  // steady_clock is CLOCK_MONOTONIC here
    const std::int64_t woke = steadyNs();
    if (woke - next > threshold_ns) recordStall(next, woke);
    if (woke - next > period_ns) next = woke;  // after a stall, do not run the missed periods back to back
  }
}

void StallProbe::recordStall(std::int64_t from_ns, std::int64_t to_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  ring_[next_] = {from_ns, to_ns};
  next_ = (next_ + 1) % ring_.size();
  count_ = std::min(count_ + 1, ring_.size());
  ++stalls_;
  max_stall_ns_ = std::max(max_stall_ns_, to_ns - from_ns);
  total_stall_ns_ += to_ns - from_ns;
}

std::int64_t StallProbe::stalledWithinNs(std::int64_t t0, std::int64_t t1) const {
  if (t1 <= t0) return 0;
  // The stalls overlapping [t0, t1], clipped; their union's length (a few at most: a fixed buffer).
  std::array<std::pair<std::int64_t, std::int64_t>, 64> hits;
  std::size_t n = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < count_ && n < hits.size(); ++i) {
      const auto& s = ring_[i];
      if (s.second <= t0 || s.first >= t1) continue;
      hits[n++] = {std::max(s.first, t0), std::min(s.second, t1)};
    }
  }
  std::sort(hits.begin(), hits.begin() + static_cast<std::ptrdiff_t>(n));
  std::int64_t total = 0, end = t0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t from = std::max(hits[i].first, end);
    if (hits[i].second > from) {
      total += hits[i].second - from;
      end = hits[i].second;
    }
  }
  return total;
}

std::int64_t StallProbe::stalledWhileWaitingNs(std::int64_t deadline_ns, std::int64_t timeout_ns) const {
  const std::int64_t period_ns = options_.period.count() * 1000;
  return stalledWithinNs(deadline_ns - timeout_ns - period_ns, deadline_ns + period_ns);
}

std::vector<std::pair<std::int64_t, std::int64_t>> StallProbe::stallWindows() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(count_)};
}

std::uint64_t StallProbe::stalls() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stalls_;
}
double StallProbe::maxStallMs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<double>(max_stall_ns_) * 1e-6;
}
double StallProbe::totalStallMs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<double>(total_stall_ns_) * 1e-6;
}

}  // namespace mft::services
