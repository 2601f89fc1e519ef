#pragma once
// Per-tick timing statistics for service summaries: mean, p50, p99 and max over a preallocated sample buffer
// (no allocation while recording; beyond capacity only mean and max keep counting).
#include <algorithm>
#include <string>
#include <vector>

#include "common/json_writer.hpp"

namespace mft::services {

class LatencyStats {
 public:
  explicit LatencyStats(std::size_t capacity = 4'000'000) { samples_.reserve(capacity); }
  void add(double v) {
    ++count_;
    sum_ += v;
    max_ = std::max(max_, v);
    if (samples_.size() < samples_.capacity()) samples_.push_back(v);
  }
  std::size_t count() const { return count_; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  double max() const { return max_; }
  // Percentile over the stored samples (sorts a copy: call at the end of a run, not in the loop).
  double percentile(double p) const {
    if (samples_.empty()) return 0.0;
    std::vector<double> s = samples_;
    const auto k = std::min(s.size() - 1, static_cast<std::size_t>(p * static_cast<double>(s.size())));
    std::nth_element(s.begin(), s.begin() + static_cast<long>(k), s.end());
    return s[k];
  }
  // {"mean": .., "p50": .., "p99": .., "p99_9": .., "max": .., "count": ..}
  std::string json() const {
    config::JsonWriter w;
    w.beginObject().fixedField("mean", mean(), 3).fixedField("p50", percentile(0.5), 3);
    w.fixedField("p99", percentile(0.99), 3).fixedField("p99_9", percentile(0.999), 3).fixedField("max", max(), 3).field("count", count_);
    return w.endObject().str();
  }

 private:
  std::vector<double> samples_;
  std::size_t count_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
};

}  // namespace mft::services
