#include "services/sim/recorder_flow.hpp"

#include <algorithm>
#include <cstdio>

#include "services/runtime/process.hpp"

namespace mft::services {

using Clock = std::chrono::steady_clock;

RecorderFlow::RecorderFlow(ServiceContext& ctx, std::uint64_t window, std::mutex& mutex,
                           std::condition_variable& changed)
    : window_(window), mutex_(mutex), changed_(changed) {
  if (window == 0 || !ctx.lockstep()) return;
  reader_ = std::make_unique<TopicReader<msg::RecorderProgress, msg::RecorderProgressPubSubType>>(
      ctx.reading("RecorderProgress"), [this](const msg::RecorderProgress& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        heard_ = true;
        tick_ = std::max(tick_, m.tick());
        all_topics_tick_ = std::max(all_topics_tick_, m.all_topics_tick());
        changed_.notify_all();
      });
}

bool RecorderFlow::awaitWindow(std::uint64_t k, std::chrono::duration<double> timeout, std::string* error) {
  if (!reader_) return true;
  std::unique_lock<std::mutex> lock(mutex_);
  if (k <= tick_ + window_) return true;
  ++waits_;
  const auto t0 = Clock::now();
  const auto deadline = t0 + timeout;
  while (k > tick_ + window_ && !shutdownRequested() && Clock::now() < deadline)
    changed_.wait_for(lock, std::chrono::milliseconds(10));
  wait_s_ += std::chrono::duration<double>(Clock::now() - t0).count();
  if (k <= tick_ + window_ || shutdownRequested()) return true;
  char buf[200];
  std::snprintf(buf, sizeof buf, "timeout: mft-record confirmed only tick %llu of %llu within %.1f s (is it running?)",
                static_cast<unsigned long long>(tick_), static_cast<unsigned long long>(k), timeout.count());
  *error = buf;
  return false;
}

bool RecorderFlow::awaitComplete(std::uint64_t last_tick) {
  if (!reader_) return true;
  std::unique_lock<std::mutex> lock(mutex_);
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  while (all_topics_tick_ < last_tick && !shutdownRequested() && Clock::now() < deadline)
    changed_.wait_for(lock, std::chrono::milliseconds(10));
  return all_topics_tick_ >= last_tick;
}

}  // namespace mft::services
