#pragma once
// Live tuning on the service side (docs/guide/live-tuning.md): mft-wbc and mft-planner read ConfigChange requests
// (mft-cmd --set), judge each off the control loop with their configuration's strict loader, answer on
// CommandVerdict (rejected with the loader's message, or scheduled), and swap the judged parameters in at a tick
// boundary: in lockstep at the first tick at or after the requested simulated time (a time already passed is
// refused, so a run stays reproducible), in realtime at the next tick when no time is given. Each applied change
// is published as a ConfigChange with applied = true and its tick (the recorder keeps it for
// mft-replay --through-wbc) and listed in <service>.tuning.json beside the service's summary (what
// `mft-supervisor status` shows). The tick path only copies preallocated slots: the DDS write of the applied
// record and the status file are done by a thread of this class.
#include <algorithm>
#include <cmath>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/json_writer.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/runtime/topic_qos.hpp"

namespace mft::services {

// <dir>/<service>.tuning.json for a summary file <dir>/<service>.summary.json ("" without a summary file).
std::string tuningStatusFile(const std::string& summary_file);
// Writes the status file (never half-written); returns false on failure.
bool writeTuningStatus(const std::string& path, const std::string& json);
// The text of configuration file `path` as the loaders read it (the active profiles applied). Throws
// config::ConfigError when it cannot be read.
std::string configTextInForce(const std::string& path);

// What a service with live changes loads before its endpoints exist: its node, and the text of its configuration
// file as loaded (the active profiles applied), the base of live changes.
template <class Node>
struct TunableNode {
  std::unique_ptr<Node> node;
  std::string config_text;
};

template <class Tuning>
class LiveTuning {
 public:
  struct Judged {
    Tuning tuning{};              // the parameters with the change (and every change accepted before it)
    std::string yaml_text;        // the configuration with the change (the base of the next one)
    std::vector<double> value, previous;
  };
  // Judges key = value_yaml against the configuration text in force; returns the judged parameters or throws
  // with the reason (the strict loader's message). Called off the loop, one request at a time.
  using Judge = std::function<Judged(const std::string& yaml_text, const std::string& key, const std::string& value_yaml)>;

  // yaml_text: the configuration the service loaded (profiles applied).
  LiveTuning(DdsParticipant& participant, const char* service, std::uint8_t target, std::uint8_t verdict_source,
             bool lockstep, const std::string& status_file, std::string yaml_text, Judge judge)
      : current_text_(std::move(yaml_text)),
        service_(service),
        target_(target),
        lockstep_(lockstep),
        status_file_(status_file),
        judge_(std::move(judge)),
        verdicts_(participant, service, verdict_source) {
    // A secured stack whose permissions predate ConfigChange runs on without live tuning, with a warning.
    try {
      applied_writer_ = std::make_unique<TopicWriter<msg::ConfigChange, msg::ConfigChangePubSubType>>(
          participant, "ConfigChange", serviceWriterProfile("ConfigChange", lockstep));
    } catch (const DdsError& e) {
      std::fprintf(stderr, "%s: warning: %s: applied live changes are not published (nor recorded)\n", service_, e.what());
    }
    worker_ = std::thread([this] { run(); });
    try {
      reader_ = std::make_unique<TopicReader<msg::ConfigChange, msg::ConfigChangePubSubType>>(
          participant, "ConfigChange", serviceReaderProfile("ConfigChange", lockstep),
          [this](const msg::ConfigChange& m) { onRequest(m); });
    } catch (const DdsError& e) {
      std::fprintf(stderr, "%s: warning: %s: no live tuning\n", service_, e.what());
    }
    writeStatus();  // an empty list: status shows that this service takes live changes
  }
  ~LiveTuning() {
    reader_.reset();
    stopWorker(mutex_, stop_, wake_, worker_);
    if (applied_writer_) applied_writer_->waitForAcknowledgments(std::chrono::milliseconds(1000));
  }
  LiveTuning(const LiveTuning&) = delete;
  LiveTuning& operator=(const LiveTuning&) = delete;

  // The tick boundary: call before the tick's computation, in the tick path. Applies, in order, every judged
  // change due at this tick through set(const Tuning&). Allocation-free.
  template <class Set>
  void applyDue(std::uint64_t tick, double time_s, std::uint64_t stamp_ns, Set&& set) {
    std::lock_guard<std::mutex> lock(mutex_);
    now_s_ = time_s;
    last_tick_ = tick;
    std::size_t done = 0;
    for (; done < pending_count_; ++done) {
      Pending& p = pending_[done];
      if (p.at_s > 0.0 && p.at_s > time_s + 1e-9) break;  // not yet (the queue is in time order)
      set(p.tuning);
      ++applied_;
      msg::ConfigChange& r = p.record;
      r.applied(true);
      r.tick(tick);
      r.stamp_ns(stamp_ns);
      verdicts_.post(r.seq(), msg::VERDICT_APPLIED, tick, stamp_ns, "%s = %s in force from tick %llu (t = %.3f s)",
                     r.key().data(), p.value_text.data(), static_cast<unsigned long long>(tick), time_s);
      if (done_count_ < done_.size()) done_[(done_head_ + done_count_++) % done_.size()] = p;
    }
    if (done == 0) return;
    for (std::size_t i = done; i < pending_count_; ++i) pending_[i - done] = pending_[i];
    pending_count_ -= done;
    wake_.notify_one();
  }

  std::uint64_t received() const { return received_.load(); }
  std::uint64_t rejected() const { return rejected_.load(); }
  std::uint64_t applied() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return applied_;
  }
  std::string summaryJson() const {
    config::JsonWriter w;
    w.beginObject().field("received", received()).field("rejected", rejected()).field("applied", applied());
    return w.endObject().str();
  }

 private:
  struct Pending {
    Tuning tuning{};
    double at_s = 0.0;
    msg::ConfigChange record;
    std::array<char, 64> value_text{}, previous_text{};
  };

  static std::string text(const std::array<char, 64>& a) { return std::string(a.data(), strnlen(a.data(), a.size())); }

  void reject(const msg::ConfigChange& m, const std::string& why) {
    ++rejected_;
    std::fprintf(stderr, "%s: live change seq %llu (%s) rejected: %s\n", service_, static_cast<unsigned long long>(m.seq()),
                 text(m.key()).c_str(), why.c_str());
    std::uint64_t tick;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tick = last_tick_;
    }
    verdicts_.post(m.seq(), msg::VERDICT_REJECTED, tick, 0, "%s", why.c_str());
  }

  void onRequest(const msg::ConfigChange& m) {
    if (m.applied() || m.target() != target_) return;  // an applied record, or the other service's change
    ++received_;
    const std::string key = text(m.key()), value = text(m.value());
    if (!std::isfinite(m.at_s()) || m.at_s() < 0.0) return reject(m, "the time to apply at is not a time >= 0");
    if (lockstep_ && m.at_s() <= 0.0)
      return reject(m, "a lockstep stack takes a change at a stated simulated time only (mft-cmd --at T), so that "
                       "the run stays reproducible");
    Pending p;
    Judged j;
    try {
      // Judged against the configuration with every change accepted so far (applied or waiting).
      j = judge_(current_text_, key, value);
    } catch (const std::exception& e) {
      return reject(m, e.what());
    }
    p.tuning = j.tuning;
    fill(p.value_text, j.value);
    fill(p.previous_text, j.previous);
    p.record = m;
    p.record.count(static_cast<std::uint8_t>(std::min<std::size_t>(j.value.size(), 2)));
    for (std::size_t i = 0; i < 2; ++i) p.record.number()[i] = i < j.value.size() ? j.value[i] : 0.0;
    p.at_s = m.at_s();
    char why[160] = "";
    std::uint64_t tick;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tick = last_tick_;
      const double last_at = pending_count_ ? pending_[pending_count_ - 1].at_s : 0.0;
      if (p.at_s > 0.0 && p.at_s <= now_s_ + 1e-9)
        std::snprintf(why, sizeof why, "t = %.3f s has passed (the stack is at t = %.3f s): give a later --at", p.at_s,
                      now_s_);
      else if (pending_count_ == pending_.size())
        std::snprintf(why, sizeof why, "too many changes waiting for their tick");
      else if (pending_count_ && (p.at_s < last_at || (p.at_s <= 0.0 && last_at > 0.0)))
        std::snprintf(why, sizeof why, "a change for t = %.3f s is waiting: give --at >= %.3f", last_at, last_at);
      else
        pending_[pending_count_++] = p;
    }
    if (why[0]) return reject(m, why);
    current_text_ = j.yaml_text;
    if (p.at_s > 0.0)
      verdicts_.post(m.seq(), msg::VERDICT_SCHEDULED, tick, 0, "%s = %s (was %s) accepted: in force from t = %.3f s",
                     key.c_str(), p.value_text.data(), p.previous_text.data(), p.at_s);
    else
      verdicts_.post(m.seq(), msg::VERDICT_SCHEDULED, tick, 0, "%s = %s (was %s) accepted: in force from the next tick",
                     key.c_str(), p.value_text.data(), p.previous_text.data());
  }

  static void fill(std::array<char, 64>& out, const std::vector<double>& v);

  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || done_count_ > 0; });
      if (done_count_ == 0) return;
      const Pending p = done_[done_head_];
      done_head_ = (done_head_ + 1) % done_.size();
      --done_count_;
      lock.unlock();
      if (applied_writer_) applied_writer_->write(p.record);
      const double time_s = static_cast<double>(p.record.stamp_ns()) * 1e-9;
      std::printf("%s: live change seq %llu applied at tick %llu (t = %.3f s): %s = %s (was %s)\n", service_,
                  static_cast<unsigned long long>(p.record.seq()), static_cast<unsigned long long>(p.record.tick()),
                  time_s, p.record.key().data(), p.value_text.data(), p.previous_text.data());
      std::fflush(stdout);
      config::JsonWriter change;
      change.beginObject().field("seq", p.record.seq()).field("key", text(p.record.key()));
      change.field("value", text(p.value_text)).field("previous", text(p.previous_text)).field("tick", p.record.tick());
      history_.push_back(change.fixedField("time_s", time_s, 6).endObject().str());
      writeStatus();
      lock.lock();
    }
  }

  void writeStatus() {
    if (status_file_.empty()) return;
    config::JsonWriter w;
    w.beginObject().field("service", service_).key("applied").beginArray();
    for (const auto& change : history_) w.raw(change);
    writeTuningStatus(status_file_, w.endArray().endObject().str());
  }

  std::string current_text_;  // reader-thread only: the configuration with every accepted change
  const char* service_;
  std::uint8_t target_;
  bool lockstep_;
  std::string status_file_;
  Judge judge_;
  VerdictPublisher verdicts_;
  std::unique_ptr<TopicWriter<msg::ConfigChange, msg::ConfigChangePubSubType>> applied_writer_;
  std::unique_ptr<TopicReader<msg::ConfigChange, msg::ConfigChangePubSubType>> reader_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::array<Pending, 16> pending_{};
  std::size_t pending_count_ = 0;
  std::array<Pending, 16> done_{};
  std::size_t done_head_ = 0, done_count_ = 0;
  std::uint64_t applied_ = 0, last_tick_ = 0;
  double now_s_ = -std::numeric_limits<double>::infinity();
  std::atomic<std::uint64_t> received_{0}, rejected_{0};
  bool stop_ = false;
  std::vector<std::string> history_;  // worker-thread only: each applied change as JSON
  std::thread worker_;
};

template <class Tuning>
void LiveTuning<Tuning>::fill(std::array<char, 64>& out, const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.10g", v[i]);
    s += (i ? ", " : "") + std::string(buf);
  }
  if (v.size() > 1) s = "[" + s + "]";
  if (v.empty()) s = "?";
  std::snprintf(out.data(), out.size(), "%s", s.c_str());
}

}  // namespace mft::services
