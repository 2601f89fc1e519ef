#include "tools/mft-cmd/live_set.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_io.hpp"
#include "tools/mft-cmd/cmd_common.hpp"
#include "tools/mft-cmd/delivery.hpp"

namespace mft::cmd {

namespace {

struct Change {
  std::string file, key, value, answerer;
  std::uint8_t source = 0;
  msg::ConfigChange msg;
  std::vector<Verdict> verdicts;
  Reach reach;  // which of the stack's readers acknowledged it
  std::string result = "no_verdict";
  int code = kNoVerdict;
};

// FILE.KEY=VALUE to a change with its seq; a malformed item is a usage error naming it.
Change parseChange(const config::CommandLine& cli, const std::string& item, std::uint64_t seq, double at_s) {
  Change c;
  try {
    const config::SetItem s = config::parseSetItem(item, c.msg.key().size());
    c.file = s.file, c.key = s.key, c.value = s.value;
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (c.file == "wbc") {
    c.answerer = "mft-wbc";
    c.source = msg::COMMAND_SOURCE_WBC;
    c.msg.target(msg::CONFIG_TARGET_WBC);
  } else {
    c.answerer = "mft-planner";
    c.source = msg::COMMAND_SOURCE_PLANNER;
    c.msg.target(msg::CONFIG_TARGET_PLANNER);
  }
  c.msg.seq(seq);
  std::snprintf(c.msg.key().data(), c.msg.key().size(), "%s", c.key.c_str());
  std::snprintf(c.msg.value().data(), c.msg.value().size(), "%s", c.value.c_str());
  c.msg.at_s(at_s);
  c.msg.applied(false);
  return c;
}

class LiveSet {
 public:
  explicit LiveSet(const config::CommandLine& cli)
      : cli_(cli), x_(exchangeOptions(cli)), base_seq_(commandSeq(cli, 0xfffu, 4)),
        at_s_(cli.getDouble("at", 0.0, 1e6)) {
    for (const std::string& item : cli.getAll("set")) {
      Change c = parseChange(cli, item, base_seq_ + changes_.size(), at_s_);
      if (changes_.size() >= 16) cli.fail("--set: at most 16 changes at once");
      try {  // the key's range and unit (common/config_schema) before anything is sent
        config::checkLiveValue(c.file, c.key, c.value, "--set '" + item + "'");
      } catch (const config::ConfigError& e) {
        cli.fail(e.what());
      }
      changes_.push_back(std::move(c));
    }
  }

  int run() {
    return withParticipant(
        cli_, x_.domain, [this](services::DdsParticipant& p) { return exchange(p); },
        [this](int code, const std::string& result, const std::string& error) { return finish(code, result, error); });
  }

 private:
  using Writer = services::TopicWriter<msg::ConfigChange, msg::ConfigChangePubSubType>;

  // One line on stderr (and the JSON object on stdout with --json) for every outcome.
  int finish(int code, const std::string& result, std::string error) {
    if (!changes_.empty() && changes_.front().reach.known) acknowledged_ = true;  // recounted below
    for (auto& c : changes_) {
      if (!c.verdicts.empty()) c.reach.confirmedBy(c.answerer);  // its verdict proves it has the change
      if (c.reach.known) acknowledged_ = acknowledged_ && c.reach.complete();
      if ((code == kAccepted || code == kRejected || code == kNotDelivered) && !c.reach.complete()) {
        code = kNotDelivered;
        error += (error.empty() ? "" : "; ") + c.file + "." + c.key + " (seq " + std::to_string(c.msg.seq()) +
                 ") did not reach every reader of the stack: " + c.reach.missedText();
      }
    }
    if (!error.empty()) std::fprintf(stderr, "mft-cmd: %s\n", error.c_str());
    if (x_.json) {
      config::JsonWriter w;
      w.beginObject().field("command", "ConfigChange").field("domain", x_.domain).field("at_s", at_s_, 6);
      w.field("readers_matched", matched_).field("acknowledged", acknowledged_).key("changes").beginArray();
      for (const auto& c : changes_) {
        w.beginObject().field("file", c.file).field("key", c.key).field("value", c.value).field("seq", c.msg.seq());
        c.reach.writeJson(w);
        w.field("answered_by", c.answerer).key("verdicts");
        writeVerdicts(w, c.verdicts);
        w.field("result", c.result).endObject();
      }
      w.endArray().field("result", result).field("exit_code", code).field("error", error);
      std::printf("%s\n", w.endObject().str().c_str());
    }
    std::fflush(stdout);
    return code;
  }

  void onVerdict(const msg::CommandVerdict& m) {
    if (m.seq() < base_seq_ || m.seq() >= base_seq_ + changes_.size()) return;
    const std::size_t i = static_cast<std::size_t>(m.seq() - base_seq_);
    if (m.source() != changes_[i].source) return;
    std::lock_guard<std::mutex> lock(mutex_);
    received_[i].push_back(verdictOf(m, written_at_[i]));
  }

  int exchange(services::DdsParticipant& participant) {
    received_.assign(changes_.size(), {});
    written_at_.assign(changes_.size(), Clock::now());
    services::TopicReader<msg::CommandVerdict, msg::CommandVerdictPubSubType> verdict_reader(
        participant, "CommandVerdict", "event_reader", [this](const msg::CommandVerdict& m) { onVerdict(m); });
    // One writer per change: the command writer keeps one sample (KEEP_LAST 1, transient local), so a reader that
    // matches only after the writes (discovery reports the WBC's and the planner's readers one at a time) still
    // gets every change, not only the last one.
    std::vector<std::unique_ptr<Writer>> writers;
    for (std::size_t i = 0; i < changes_.size(); ++i)
      writers.push_back(std::make_unique<Writer>(participant, "ConfigChange", "command_writer"));
    const auto all_matched = [&] {
      for (const auto& w : writers)
        if (w->matched() == 0) return false;
      return true;
    };
    if (!services::waitUntil(all_matched, x_.timeout))
      return finish(kNoStack, "no_stack",
                    "no stack answered on domain " + std::to_string(x_.domain) + " within " + fmt(x_.timeout_s, -6) +
                        " s (no reader of ConfigChange; is the stack up on this domain?)");
    for (std::size_t i = 0; i < changes_.size(); ++i) {
      written_at_[i] = Clock::now();
      if (!writers[i]->write(changes_[i].msg)) return finish(kUsage, "error", "the DDS writer refused the ConfigChange");
    }
    deliver(participant, writers);
    matched_ = writers.front()->matched();
    if (!x_.json) {
      std::printf("mft-cmd: %zu ConfigChange(s) (%s) written to %d reader(s) on domain %d, %s\n", changes_.size(),
                  at_s_ > 0 ? ("at t = " + fmt(at_s_, 3) + " s").c_str() : "at the next tick", matched_, x_.domain,
                  ackText().c_str());
      std::fflush(stdout);
    }
    return awaitVerdicts();
  }

  // Every reader the stack has (the recorder included) must acknowledge every change within --timeout.
  void deliver(const services::DdsParticipant& participant, const std::vector<std::unique_ptr<Writer>>& writers) {
    std::vector<std::unique_ptr<WriterAcks<Writer>>> acks;
    std::vector<AckSource*> sources;
    for (const auto& w : writers) sources.push_back(acks.emplace_back(std::make_unique<WriterAcks<Writer>>(*w)).get());
    std::vector<std::string> answerers;
    for (const auto& c : changes_)
      if (std::find(answerers.begin(), answerers.end(), c.answerer) == answerers.end()) answerers.push_back(c.answerer);
    const std::vector<Reach> reaches =
        awaitDelivery(participant, "ConfigChange", sources, answerers, written_at_.back() + x_.timeout);
    acknowledged_ = true;
    for (std::size_t i = 0; i < changes_.size(); ++i) {
      changes_[i].reach = reaches[i];
      acknowledged_ = acknowledged_ && reaches[i].complete();
    }
  }

  // One text when every change reached the same services (the usual case), else one per change.
  std::string ackText() const {
    const std::string first = changes_.front().reach.ackText();
    const bool same = std::all_of(changes_.begin(), changes_.end(), [&](const Change& c) { return c.reach.ackText() == first; });
    if (same) return first;
    std::string text;
    for (const auto& c : changes_) text += (text.empty() ? "" : "; ") + ("seq " + std::to_string(c.msg.seq()) + " ") + c.reach.ackText();
    return text;
  }

  int awaitVerdicts() {
    const auto deadline = written_at_.back() + std::chrono::duration<double>(x_.verdict_timeout_s);
    shown_.assign(changes_.size(), 0);
    for (;;) {
      const bool open = takeVerdicts();
      std::fflush(stdout);
      if (!open || Clock::now() > deadline) break;
      if (answererMissed() && Clock::now() > written_at_.back() + x_.timeout) {
        bool any = false;
        for (const auto& c : changes_) any = any || !c.verdicts.empty();
        if (!any)
          return finish(kNotAcknowledged, "not_acknowledged",
                        "the readers of ConfigChange on domain " + std::to_string(x_.domain) +
                            " did not acknowledge within " + fmt(x_.timeout_s, -6) + " s: " + ackText());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return conclude();
  }

  bool answererMissed() const {
    for (const auto& c : changes_)
      if (c.reach.missedBy(c.answerer)) return true;
    return false;
  }

  // Reports the verdicts that arrived since the last call; true while a change is still open.
  bool takeVerdicts() {
    bool open = false;
    for (std::size_t i = 0; i < changes_.size(); ++i) {
      Change& c = changes_[i];
      {
        std::lock_guard<std::mutex> lock(mutex_);
        c.verdicts = received_[i];
      }
      for (; shown_[i] < c.verdicts.size(); ++shown_[i]) {
        const auto& v = c.verdicts[shown_[i]];
        if (v.verdict == msg::VERDICT_REJECTED) {
          c.result = "rejected";
          c.code = kRejected;
          std::fprintf(stderr, "mft-cmd: %s rejected %s.%s=%s (seq %llu): %s\n", c.answerer.c_str(), c.file.c_str(),
                       c.key.c_str(), c.value.c_str(), static_cast<unsigned long long>(c.msg.seq()), v.reason.c_str());
        } else {
          if (!x_.json)
            std::printf("%s: %s.%s %s at tick %llu: %s\n", c.answerer.c_str(), c.file.c_str(), c.key.c_str(),
                        services::verdictName(v.verdict), static_cast<unsigned long long>(v.tick), v.reason.c_str());
          c.result = v.verdict == msg::VERDICT_APPLIED ? "applied" : "scheduled";
          c.code = kAccepted;
        }
      }
      const bool settled =
          c.result == "applied" || c.result == "rejected" || (x_.accepted_only && c.result == "scheduled");
      open = open || !settled;
    }
    return open;
  }

  // The worst change decides the exit status and the result.
  int conclude() {
    int code = kAccepted;
    std::string error;
    for (const auto& c : changes_) {
      if (c.code == kNoVerdict)
        error += std::string(error.empty() ? "" : "; ") + "no verdict from " + c.answerer + " on " + c.file + "." +
                 c.key + " (seq " + std::to_string(c.msg.seq()) + ") within " + fmt(x_.verdict_timeout_s, -6) +
                 " s (is " + c.answerer + " running?)";
      if (c.code == kRejected && code != kNoVerdict) code = kRejected;
      if (c.code == kNoVerdict) code = kNoVerdict;
      if (!x_.json && c.result == "scheduled" && !x_.accepted_only)
        std::printf("mft-cmd: %s.%s accepted by %s, not applied within %g s (it stays scheduled)\n", c.file.c_str(),
                    c.key.c_str(), c.answerer.c_str(), x_.verdict_timeout_s);
    }
    std::string result = "applied";
    for (const auto& c : changes_)
      if (c.result != "applied") result = c.result == "scheduled" && result == "applied" ? "scheduled" : result;
    if (code == kRejected) result = "rejected";
    if (code == kNoVerdict) result = "no_verdict";
    return finish(code, result, error);
  }

  const config::CommandLine& cli_;
  const Exchange x_;
  const std::uint64_t base_seq_;
  const double at_s_;
  std::vector<Change> changes_;
  int matched_ = 0;
  bool acknowledged_ = false;
  std::mutex mutex_;
  std::vector<std::vector<Verdict>> received_;
  std::vector<Clock::time_point> written_at_;
  std::vector<std::size_t> shown_;
};

}  // namespace

int runSet(const config::CommandLine& cli) { return LiveSet(cli).run(); }

}  // namespace mft::cmd
