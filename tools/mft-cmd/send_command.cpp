#include "tools/mft-cmd/send_command.hpp"

#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "idl/msg_pubsub.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_io.hpp"
#include "tools/mft-cmd/cmd_common.hpp"
#include "tools/mft-cmd/delivery.hpp"

namespace mft::cmd {

namespace {

// The command, and how it is described in the output.
struct Outgoing {
  bool is_command = false;  // an OperatorCommand, else a Disturbance
  msg::OperatorCommand command;
  msg::Disturbance push;
  std::string topic, answerer, what_text, mode;
  std::uint8_t source = 0;

  bool liftoff() const { return push.trigger() == msg::TRIGGER_AT_NEXT_LIFTOFF; }
  // The command's fields in the JSON.
  void writeWhat(config::JsonWriter& w) const {
    if (is_command) {
      w.field("mode", mode).field("z_cmd", command.z_cmd(), 6).field("v_cmd", command.v_cmd(), 6);
    } else {
      w.field("impulse_Ns", push.impulse(), 6).field("trigger", liftoff() ? "at_next_liftoff" : "at_time");
      w.field("time_s", push.time_s(), 6).field("leg", push.leg());
    }
  }
};

Outgoing operatorCommand(const config::CommandLine& cli, std::uint64_t seq) {
  Outgoing o;
  o.is_command = true;
  o.mode = cli.get("mode");
  if (o.mode == "stand") o.command.mode(msg::LOCOMOTION_STAND);
  else if (o.mode == "step_in_place") o.command.mode(msg::LOCOMOTION_STEP_IN_PLACE);
  else if (o.mode == "walk") o.command.mode(msg::LOCOMOTION_WALK);
  else cli.fail("--mode: unknown mode '" + o.mode + "' (stand, step_in_place or walk)");
  o.command.seq(seq);
  o.command.z_cmd(cli.getDouble("height", -100.0, 100.0));
  o.command.v_cmd(cli.getDouble("speed", -100.0, 100.0));
  o.topic = "OperatorCommand";
  o.answerer = "mft-planner";
  o.source = msg::COMMAND_SOURCE_PLANNER;
  o.what_text = o.mode + ", height " + fmt(o.command.z_cmd(), 3) + " m, speed " + fmt(o.command.v_cmd(), 3) + " m/s";
  return o;
}

Outgoing disturbance(const config::CommandLine& cli, std::uint64_t seq) {
  Outgoing o;
  o.push.seq(seq);
  o.push.impulse(cli.getDouble("push", -1e4, 1e4));
  o.push.time_s(cli.getDouble("at", 0.0, 1e6));
  o.push.trigger(msg::TRIGGER_AT_TIME);
  o.push.leg(-1);
  if (cli.isSet("at-liftoff")) {
    const std::string leg = cli.get("at-liftoff");
    if (leg != "right" && leg != "left") cli.fail("--at-liftoff: expected right or left");
    o.push.trigger(msg::TRIGGER_AT_NEXT_LIFTOFF);
    o.push.leg(static_cast<std::int16_t>(leg == "right" ? 0 : 1));
  }
  o.topic = "Disturbance";
  o.answerer = "mft-sim";
  o.source = msg::COMMAND_SOURCE_SIMULATOR;
  o.what_text = fmt(o.push.impulse(), 3) + " N s " +
                (o.liftoff() ? std::string("at the next ") + (o.push.leg() == 0 ? "right" : "left") + "-foot lift-off"
                 : cli.isSet("at") ? "at t = " + fmt(o.push.time_s(), 3) + " s"
                                   : std::string("now"));
  return o;
}

class CommandSend {
 public:
  explicit CommandSend(const config::CommandLine& cli)
      : cli_(cli), x_(exchangeOptions(cli)), seq_(commandSeq(cli, 0xffffu, 0)),
        out_(cli.isSet("mode") ? operatorCommand(cli, seq_) : disturbance(cli, seq_)) {}

  int run() {
    return withParticipant(
        cli_, x_.domain, [this](services::DdsParticipant& p) { return exchange(p); },
        [this](int code, const std::string& result, const std::string& error) { return finish(code, result, error); });
  }

 private:
  // One line on stderr (and the JSON object on stdout with --json) for every outcome.
  int finish(int code, const std::string& result, std::string error) {
    if (!verdicts_.empty()) reach_.confirmedBy(out_.answerer);  // its verdict proves it has the command
    if (reach_.known) acknowledged_ = reach_.complete();
    if ((code == kAccepted || code == kRejected) && !reach_.complete()) {
      code = kNotDelivered;
      error += (error.empty() ? "" : "; ") + out_.topic + " seq " + std::to_string(seq_) +
               " did not reach every reader of the stack: " + reach_.missedText();
    }
    if (!error.empty()) std::fprintf(stderr, "mft-cmd: %s\n", error.c_str());
    if (x_.json) {
      config::JsonWriter w;
      w.beginObject().field("command", out_.topic).field("seq", seq_).field("domain", x_.domain);
      out_.writeWhat(w);
      w.field("readers_matched", matched_).field("acknowledged", acknowledged_);
      reach_.writeJson(w);
      w.field("answered_by", out_.answerer);
      w.key("verdicts");
      writeVerdicts(w, verdicts_);
      w.field("result", result).field("exit_code", code).field("error", error);
      std::printf("%s\n", w.endObject().str().c_str());
    }
    std::fflush(stdout);
    return code;
  }

  int exchange(services::DdsParticipant& participant) {
    // The verdict reader exists before the command is written; the stack's verdict writers are transient
    // local, so a verdict written before this reader matched them still arrives.
    services::TopicReader<msg::CommandVerdict, msg::CommandVerdictPubSubType> verdict_reader(
        participant, "CommandVerdict", "event_reader", [this](const msg::CommandVerdict& m) {
          if (m.seq() != seq_ || m.source() != out_.source) return;  // another command's, or the other service's
          std::lock_guard<std::mutex> lock(mutex_);
          received_.push_back(verdictOf(m, written_at_));
        });
    std::unique_ptr<services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType>> command_writer;
    std::unique_ptr<services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType>> push_writer;
    const bool has_cmd = out_.is_command;
    if (has_cmd)
      command_writer = std::make_unique<services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType>>(
          participant, out_.topic, "command_writer");
    else
      push_writer = std::make_unique<services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType>>(
          participant, out_.topic, "command_writer");
    const auto readers = [&] { return has_cmd ? command_writer->matched() : push_writer->matched(); };

    if (!services::waitUntil([&] { return readers() > 0; }, x_.timeout))
      return finish(kNoStack, "no_stack",
                    "no stack answered on domain " + std::to_string(x_.domain) + " within " + fmt(x_.timeout_s, -6) +
                        " s (no reader of " + out_.topic + "; is the stack up on this domain?)");
    written_at_ = Clock::now();
    const bool written = has_cmd ? command_writer->write(out_.command) : push_writer->write(out_.push);
    if (!written) return finish(kUsage, "error", "the DDS writer refused the " + out_.topic);
    // Every reader the stack has (the recorder included) must acknowledge it within --timeout (delivery.hpp).
    reach_ = has_cmd ? deliver(participant, *command_writer) : deliver(participant, *push_writer);
    acknowledged_ = reach_.complete();
    matched_ = readers();
    if (!x_.json) {
      std::printf("mft-cmd: %s seq %llu (%s) written to %d reader(s) on domain %d, %s\n", out_.topic.c_str(),
                  static_cast<unsigned long long>(seq_), out_.what_text.c_str(), matched_, x_.domain,
                  reach_.ackText().c_str());
      std::fflush(stdout);
    }
    return awaitVerdict();
  }

  template <class Writer>
  Reach deliver(const services::DdsParticipant& participant, Writer& writer) {
    WriterAcks<Writer> acks(writer);
    return awaitDelivery(participant, out_.topic, {&acks}, {out_.answerer}, written_at_ + x_.timeout).front();
  }

  // The verdicts: rejected, or scheduled then applied.
  int awaitVerdict() {
    const std::string seq = std::to_string(seq_);
    const auto verdict_deadline = written_at_ + std::chrono::duration<double>(x_.verdict_timeout_s);
    std::size_t shown = 0;
    bool scheduled = false;
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        verdicts_ = received_;
      }
      for (; shown < verdicts_.size(); ++shown) {
        const auto& v = verdicts_[shown];
        if (v.verdict == msg::VERDICT_REJECTED)
          return finish(kRejected, "rejected", out_.answerer + " rejected " + out_.topic + " seq " + seq + ": " + v.reason);
        if (!x_.json)
          std::printf("%s: %s at tick %llu: %s\n", out_.answerer.c_str(), services::verdictName(v.verdict),
                      static_cast<unsigned long long>(v.tick), v.reason.c_str());
        std::fflush(stdout);
        if (v.verdict == msg::VERDICT_APPLIED) return finish(kAccepted, "applied", "");
        if (v.verdict == msg::VERDICT_SCHEDULED) scheduled = true;
      }
      if (scheduled && x_.accepted_only) return finish(kAccepted, "scheduled", "");
      if (Clock::now() > verdict_deadline) break;
      if (reach_.missedBy(out_.answerer) && !scheduled && Clock::now() > written_at_ + x_.timeout)
        return finish(kNotAcknowledged, "not_acknowledged",
                      "the readers of " + out_.topic + " on domain " + std::to_string(x_.domain) +
                          " did not acknowledge seq " + seq + " within " + fmt(x_.timeout_s, -6) +
                          " s: " + reach_.missedText());
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (scheduled) {
      if (!x_.json)
        std::printf("mft-cmd: accepted by %s, not applied within %g s (it stays scheduled)\n", out_.answerer.c_str(),
                    x_.verdict_timeout_s);
      return finish(kAccepted, "scheduled", "");
    }
    return finish(kNoVerdict, "no_verdict",
                  "no verdict from " + out_.answerer + " on " + out_.topic + " seq " + seq + " within " +
                      fmt(x_.verdict_timeout_s, -6) + " s (" + (acknowledged_ ? "acknowledged" : "not acknowledged") +
                      " by " + std::to_string(matched_) + " reader(s); is " + out_.answerer + " running?)");
  }

  const config::CommandLine& cli_;
  const Exchange x_;
  const std::uint64_t seq_;
  const Outgoing out_;
  int matched_ = 0;
  bool acknowledged_ = false;
  Reach reach_;
  std::mutex mutex_;
  std::vector<Verdict> received_, verdicts_;
  Clock::time_point written_at_ = Clock::now();
};

}  // namespace

int runCommand(const config::CommandLine& cli) { return CommandSend(cli).run(); }

}  // namespace mft::cmd
