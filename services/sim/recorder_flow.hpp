#pragma once
// Lockstep recording: a starved recorder must slow the simulator down, not lose samples in its socket buffer.
// mft-record publishes its progress; the simulator never runs more than `window` ticks ahead of it, holds tick 0
// until the recorder receives every topic, and at the end waits (at most 2 s) until the recorder holds the last
// tick on every topic. Shares the command link's mutex and condition (one wait serves both).
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "idl/msg_pubsub.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::services {

class RecorderFlow {
 public:
  // Inactive (no reader, never waits) unless `window` > 0 in lockstep.
  RecorderFlow(ServiceContext& ctx, std::uint64_t window, std::mutex& mutex, std::condition_variable& changed);

  bool active() const { return reader_ != nullptr; }
  // Under the mutex: the recorder receives every 1 kHz topic (always true when inactive).
  bool heardLocked() const { return !reader_ || heard_; }
  // Before tick k: waits while the recorder is more than the window behind; false (with `error`) at the timeout.
  bool awaitWindow(std::uint64_t k, std::chrono::duration<double> timeout, std::string* error);
  // After the run: whether the recorder confirmed `last_tick` on every topic within 2 s (true when inactive).
  bool awaitComplete(std::uint64_t last_tick);

  std::uint64_t window() const { return active() ? window_ : 0; }
  std::uint64_t waits() const { return waits_; }
  double waitSeconds() const { return wait_s_; }

 private:
  std::uint64_t window_;
  std::mutex& mutex_;
  std::condition_variable& changed_;
  std::uint64_t tick_ = 0, all_topics_tick_ = 0, waits_ = 0;
  bool heard_ = false;
  double wait_s_ = 0.0;
  std::unique_ptr<TopicReader<msg::RecorderProgress, msg::RecorderProgressPubSubType>> reader_;
};

}  // namespace mft::services
