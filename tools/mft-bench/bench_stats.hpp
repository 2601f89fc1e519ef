#pragma once
// Per-call latency statistics for benchmarks: the loop times each call itself and reports mean, p50, p99 and
// max in microseconds as counters, because a control loop cares about the tail, not only the mean.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace mft::bench {

class LatencyRecorder {
 public:
  explicit LatencyRecorder(std::size_t reserve = 1 << 20) { samples_.reserve(reserve); }
  template <class F>
  void time(F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    if (samples_.size() < samples_.capacity()) samples_.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
  }
  void report(benchmark::State& state) {
    if (samples_.empty()) return;
    std::vector<double> s = samples_;
    std::sort(s.begin(), s.end());
    double sum = 0;
    for (double v : s) sum += v;
    auto pct = [&](double p) { return s[std::min(s.size() - 1, static_cast<std::size_t>(p * static_cast<double>(s.size())))]; };
    state.counters["mean_us"] = sum / static_cast<double>(s.size());
    state.counters["p50_us"] = pct(0.50);
    state.counters["p99_us"] = pct(0.99);
    state.counters["max_us"] = s.back();
  }

 private:
  std::vector<double> samples_;
};

}  // namespace mft::bench
