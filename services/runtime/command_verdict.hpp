#pragma once
// The stack's answer to an operator command (docs/guide/operator-commands.md): the planner judges OperatorCommand,
// the simulator Disturbance, and each posts a CommandVerdict (rejected with the reason, scheduled, applied at a
// tick) that mft-cmd waits for. Verdicts are judged inside the services' tick paths, which must neither
// allocate nor block on a reliable write: post() only formats into a preallocated ring, and a thread of the
// publisher writes the samples and logs one line per verdict.
#include <array>
#include <condition_variable>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/runtime/topic_qos.hpp"

namespace mft::services {

inline const char* verdictName(std::uint8_t verdict) {
  switch (verdict) {
    case msg::VERDICT_REJECTED: return "rejected";
    case msg::VERDICT_SCHEDULED: return "scheduled";
    case msg::VERDICT_APPLIED: return "applied";
  }
  return "unknown";
}

class VerdictPublisher {
 public:
  // `service` names the writer in the log lines; `source` is msg::COMMAND_SOURCE_*. A participant without the
  // permission to publish CommandVerdict (a secured stack whose material predates the topic) runs on without
  // verdicts, with a warning: mft-cmd then reports that no verdict came.
  VerdictPublisher(DdsParticipant& participant, const char* service, std::uint8_t source)
      : service_(service), source_(source) {
    try {
      writer_ = std::make_unique<TopicWriter<msg::CommandVerdict, msg::CommandVerdictPubSubType>>(
          participant, "CommandVerdict", serviceWriterProfile("CommandVerdict", false));  // an event: either mode
    } catch (const DdsError& e) {
      std::fprintf(stderr, "%s: warning: %s: operator commands get no verdict\n", service_, e.what());
    }
    thread_ = std::thread([this] { run(); });
  }
  // Publishes what is still queued and waits (at most 1 s) until mft-cmd has acknowledged it.
  ~VerdictPublisher() {
    stopWorker(mutex_, stop_, wake_, thread_);
    if (writer_) writer_->waitForAcknowledgments(std::chrono::milliseconds(1000));
  }
  VerdictPublisher(const VerdictPublisher&) = delete;
  VerdictPublisher& operator=(const VerdictPublisher&) = delete;

  // Queues a verdict on command `seq`; `format` gives the reason. Never allocates or blocks on the network.
  [[gnu::format(printf, 6, 7)]] void post(std::uint64_t seq, std::uint8_t verdict, std::uint64_t tick,
                                          std::uint64_t stamp_ns, const char* format, ...) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (count_ == ring_.size()) {
      ++dropped_;
      return;
    }
    msg::CommandVerdict& v = ring_[(head_ + count_) % ring_.size()];
    v.seq(seq);
    v.source(source_);
    v.verdict(verdict);
    v.accepted(verdict != msg::VERDICT_REJECTED);
    v.tick(tick);
    v.stamp_ns(stamp_ns);
    va_list args;
    va_start(args, format);
    std::vsnprintf(v.reason().data(), v.reason().size(), format, args);
    va_end(args);
    ++count_;
    wake_.notify_one();
  }
  std::uint64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  void run() {
    msg::CommandVerdict v;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || count_ > 0; });
      if (count_ == 0) return;  // stopping, nothing left
      v = ring_[head_];
      head_ = (head_ + 1) % ring_.size();
      --count_;
      lock.unlock();
      if (writer_) writer_->write(v);
      std::printf("%s: command seq %llu: %s at tick %llu: %s\n", service_, static_cast<unsigned long long>(v.seq()),
                  verdictName(v.verdict()), static_cast<unsigned long long>(v.tick()), v.reason().data());
      std::fflush(stdout);
      lock.lock();
    }
  }

  const char* service_;
  std::uint8_t source_;
  std::unique_ptr<TopicWriter<msg::CommandVerdict, msg::CommandVerdictPubSubType>> writer_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::array<msg::CommandVerdict, 32> ring_{};
  std::size_t head_ = 0, count_ = 0;
  std::uint64_t dropped_ = 0;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace mft::services
