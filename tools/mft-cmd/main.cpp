// mft-cmd: sends an operator command (height, speed, mode) or a disturbance (a sagittal push) to a running
// stack and reports the stack's verdict (docs/operator-commands.md): it waits until a reader of the stack has
// matched its writer (reliable, transient local), until the readers have acknowledged the sample, and until
// the planner (commands) or the simulator (pushes) has answered on CommandVerdict with the command's seq.
// The exit status says what happened; nothing is reported as done that the stack did not confirm.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "idl/msg_types.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "common/live_tuning.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

namespace {

// Exit statuses (also in --help).
constexpr int kAccepted = 0, kRejected = 1, kUsage = 2, kNoStack = 3, kNotAcknowledged = 4, kNoVerdict = 5;

// A number with `digits` decimals (fixed) or significant digits (general, digits < 0 means -digits).
std::string fmt(double a, int digits) {
  char buf[64];
  if (digits >= 0) std::snprintf(buf, sizeof buf, "%.*f", digits, a);
  else std::snprintf(buf, sizeof buf, "%.*g", -digits, a);
  return buf;
}

struct Verdict {
  std::uint8_t verdict = 0;
  std::uint64_t tick = 0, stamp_ns = 0;
  std::string reason;
  double waited_s = 0;  // since the command was written
};

// The verdicts as a JSON array.
void writeVerdicts(config::JsonWriter& w, const std::vector<Verdict>& verdicts) {
  w.beginArray();
  for (const auto& x : verdicts) {
    w.beginObject().field("verdict", services::verdictName(x.verdict)).field("tick", x.tick);
    w.fixedField("time_s", static_cast<double>(x.stamp_ns) * 1e-9, 4).field("reason", x.reason);
    w.fixedField("after_s", x.waited_s, 3).endObject();
  }
  w.endArray();
}

}  // namespace

// --set: one ConfigChange per FILE.KEY=VALUE, written in order (each acknowledged before the next: the command
// writer keeps one sample), then every verdict awaited. Exit status: the worst of the changes.
static int runSet(const services::CommandLine& cli) {
  struct Change {
    std::string file, key, value, answerer;
    std::uint8_t source = 0;
    msg::ConfigChange msg;
    std::vector<Verdict> verdicts;
    std::string result = "no_verdict";
    int code = kNoVerdict;
  };
  const int domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  const auto base_seq = cli.isSet("seq")
                            ? static_cast<std::uint64_t>(cli.getInt("seq", 0, 1L << 62))
                            : (static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch() /
                                                          std::chrono::milliseconds(1))
                               << 16) | ((static_cast<std::uint64_t>(getpid()) & 0xfffu) << 4);
  const double at_s = cli.getDouble("at", 0.0, 1e6);
  const double timeout_s = cli.getDouble("timeout", 0.1, 600);
  const double verdict_timeout_s = cli.getDouble("verdict-timeout", 0.1, 3600);
  const auto timeout = std::chrono::milliseconds(static_cast<long>(timeout_s * 1000));
  const bool json = cli.isSet("json");
  const bool accepted_only = cli.isSet("accepted-only");

  std::vector<Change> changes;
  for (const std::string& item : cli.getAll("set")) {
    const auto eq = item.find('='), dot = item.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
      cli.fail("--set '" + item + "': expected FILE.KEY=VALUE, e.g. wbc.weights.slack=1e5");
    Change c;
    c.file = item.substr(0, dot);
    c.key = item.substr(dot + 1, eq - dot - 1);
    c.value = item.substr(eq + 1);
    if (c.file == "wbc") {
      c.answerer = "mft-wbc";
      c.source = msg::COMMAND_SOURCE_WBC;
      c.msg.target(msg::CONFIG_TARGET_WBC);
    } else if (c.file == "planner") {
      c.answerer = "mft-planner";
      c.source = msg::COMMAND_SOURCE_PLANNER;
      c.msg.target(msg::CONFIG_TARGET_PLANNER);
    } else {
      cli.fail("--set '" + item + "': '" + c.file + "' is not a live-tunable file (wbc or planner)");
    }
    if (c.value.empty()) cli.fail("--set '" + item + "': no value after '='");
    if (c.key.size() >= c.msg.key().size() || c.value.size() >= c.msg.value().size())
      cli.fail("--set '" + item + "': key and value must be shorter than 64 characters each");
    if (changes.size() >= 16) cli.fail("--set: at most 16 changes at once");
    try {
      config::checkLiveValue(c.file, c.key, c.value, "--set '" + item + "'");
    } catch (const config::ConfigError& e) {
      cli.fail(e.what());
    }
    c.msg.seq(base_seq + changes.size());
    std::snprintf(c.msg.key().data(), c.msg.key().size(), "%s", c.key.c_str());
    std::snprintf(c.msg.value().data(), c.msg.value().size(), "%s", c.value.c_str());
    c.msg.at_s(at_s);
    c.msg.applied(false);
    changes.push_back(c);
  }

  int matched = 0;
  bool acknowledged = false;
  auto finish = [&](int code, const std::string& result, const std::string& error) {
    if (!error.empty()) std::fprintf(stderr, "mft-cmd: %s\n", error.c_str());
    if (json) {
      config::JsonWriter w;
      w.beginObject().field("command", "ConfigChange").field("domain", domain).field("at_s", at_s, 6);
      w.field("readers_matched", matched).field("acknowledged", acknowledged).key("changes").beginArray();
      for (const auto& c : changes) {
        w.beginObject().field("file", c.file).field("key", c.key).field("value", c.value).field("seq", c.msg.seq());
        w.field("answered_by", c.answerer).key("verdicts");
        writeVerdicts(w, c.verdicts);
        w.field("result", c.result).endObject();
      }
      w.endArray().field("result", result).field("exit_code", code).field("error", error);
      std::printf("%s\n", w.endObject().str().c_str());
    }
    std::fflush(stdout);
    return code;
  };

  try {
    services::DdsParticipant participant(domain, cli.get("profiles"), "mft-cmd",
                                         services::SecurityOptions{cli.get("secure"), cli.get("identity")});
    std::mutex mutex;
    std::vector<std::vector<Verdict>> received(changes.size());
    std::vector<Clock::time_point> written_at(changes.size(), Clock::now());
    services::TopicReader<msg::CommandVerdict, msg::CommandVerdictPubSubType> verdict_reader(
        participant, "CommandVerdict", "event_reader", [&](const msg::CommandVerdict& m) {
          if (m.seq() < base_seq || m.seq() >= base_seq + changes.size()) return;
          const std::size_t i = static_cast<std::size_t>(m.seq() - base_seq);
          if (m.source() != changes[i].source) return;
          std::lock_guard<std::mutex> lock(mutex);
          Verdict v;
          v.verdict = m.verdict();
          v.tick = m.tick();
          v.stamp_ns = m.stamp_ns();
          v.reason.assign(m.reason().data(), strnlen(m.reason().data(), m.reason().size()));
          v.waited_s = std::chrono::duration<double>(Clock::now() - written_at[i]).count();
          received[i].push_back(v);
        });
    // One writer per change: the command writer keeps one sample (KEEP_LAST 1, transient local), so a reader that
    // matches only after the writes (discovery reports the WBC's and the planner's readers one at a time) still
    // gets every change, not only the last one.
    using Writer = services::TopicWriter<msg::ConfigChange, msg::ConfigChangePubSubType>;
    std::vector<std::unique_ptr<Writer>> writers;
    for (std::size_t i = 0; i < changes.size(); ++i)
      writers.push_back(std::make_unique<Writer>(participant, "ConfigChange", "command_writer"));
    const auto all_matched = [&] {
      for (const auto& w : writers)
        if (w->matched() == 0) return false;
      return true;
    };
    if (!services::waitUntil(all_matched, timeout))
      return finish(kNoStack, "no_stack",
                    "no stack answered on domain " + std::to_string(domain) + " within " + fmt(timeout_s, -6) +
                        " s (no reader of ConfigChange; is the stack up on this domain?)");
    acknowledged = true;  // every write's acknowledgement, below
    for (std::size_t i = 0; i < changes.size(); ++i) {
      written_at[i] = Clock::now();
      if (!writers[i]->write(changes[i].msg)) return finish(kUsage, "error", "the DDS writer refused the ConfigChange");
    }
    for (const auto& w : writers) acknowledged = w->waitForAcknowledgments(timeout) && acknowledged;
    matched = writers.front()->matched();
    if (!json) {
      std::printf("mft-cmd: %zu ConfigChange(s) (%s) written to %d reader(s) on domain %d, %s\n", changes.size(),
                  at_s > 0 ? ("at t = " + fmt(at_s, 3) + " s").c_str() : "at the next tick", matched, domain,
                  acknowledged ? "acknowledged" : "NOT acknowledged yet");
      std::fflush(stdout);
    }
    const auto deadline = written_at.back() + std::chrono::duration<double>(verdict_timeout_s);
    std::vector<std::size_t> shown(changes.size(), 0);
    for (;;) {
      bool open = false;
      for (std::size_t i = 0; i < changes.size(); ++i) {
        Change& c = changes[i];
        {
          std::lock_guard<std::mutex> lock(mutex);
          c.verdicts = received[i];
        }
        for (; shown[i] < c.verdicts.size(); ++shown[i]) {
          const auto& v = c.verdicts[shown[i]];
          if (v.verdict == msg::VERDICT_REJECTED) {
            c.result = "rejected";
            c.code = kRejected;
            std::fprintf(stderr, "mft-cmd: %s rejected %s.%s=%s (seq %llu): %s\n", c.answerer.c_str(), c.file.c_str(),
                         c.key.c_str(), c.value.c_str(), static_cast<unsigned long long>(c.msg.seq()), v.reason.c_str());
          } else {
            if (!json)
              std::printf("%s: %s.%s %s at tick %llu: %s\n", c.answerer.c_str(), c.file.c_str(), c.key.c_str(),
                          services::verdictName(v.verdict), static_cast<unsigned long long>(v.tick), v.reason.c_str());
            c.result = v.verdict == msg::VERDICT_APPLIED ? "applied" : "scheduled";
            c.code = kAccepted;
          }
        }
        const bool settled = c.result == "applied" || c.result == "rejected" || (accepted_only && c.result == "scheduled");
        open = open || !settled;
      }
      std::fflush(stdout);
      if (!open || Clock::now() > deadline) break;
      if (!acknowledged && Clock::now() > written_at.back() + timeout) {
        bool any = false;
        for (const auto& c : changes) any = any || !c.verdicts.empty();
        if (!any)
          return finish(kNotAcknowledged, "not_acknowledged",
                        "the " + std::to_string(matched) + " reader(s) of ConfigChange on domain " +
                            std::to_string(domain) + " did not acknowledge within " + fmt(timeout_s, -6) + " s");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    int code = kAccepted;
    std::string error;
    for (const auto& c : changes) {
      if (c.code == kNoVerdict)
        error += std::string(error.empty() ? "" : "; ") + "no verdict from " + c.answerer + " on " + c.file + "." + c.key +
                 " (seq " + std::to_string(c.msg.seq()) + ") within " + fmt(verdict_timeout_s, -6) + " s (is " +
                 c.answerer + " running?)";
      if (c.code == kRejected && code != kNoVerdict) code = kRejected;
      if (c.code == kNoVerdict) code = kNoVerdict;
      if (!json && c.result == "scheduled" && !accepted_only)
        std::printf("mft-cmd: %s.%s accepted by %s, not applied within %g s (it stays scheduled)\n", c.file.c_str(),
                    c.key.c_str(), c.answerer.c_str(), verdict_timeout_s);
    }
    std::string result = "applied";
    for (const auto& c : changes)
      if (c.result != "applied") result = c.result == "scheduled" && result == "applied" ? "scheduled" : result;
    if (code == kRejected) result = "rejected";
    if (code == kNoVerdict) result = "no_verdict";
    return finish(code, result, error);
  } catch (const services::DdsError& e) {
    return finish(kUsage, "error", e.what());
  }
}

static int toolMain(int argc, char** argv) {
  services::CommandLine cli(
      "mft-cmd",
      "Send an operator command or a push to a running mft-wbc stack and wait for its verdict.\n"
      "  mft-cmd --domain 0 --mode step_in_place --height 0.42 --speed 0.0\n"
      "  mft-cmd --domain 0 --push 3.0 [--at 4.5 | --at-liftoff right]\n"
      "  mft-cmd --domain 0 --set wbc.weights.slack=1e5 --set wbc.gains.base_z.kp=300 [--at 20.0]\n"
      "The planner answers commands, the simulator pushes: rejected (with the reason), scheduled (a push at a\n"
      "lift-off or a later time) or applied at a tick. mft-cmd waits for 'applied' (or a rejection) up to\n"
      "--verdict-timeout; a command still only scheduled then counts as accepted. Protocol:\n"
      "docs/operator-commands.md. --set changes a tunable key of config/wbc.yaml (answered by mft-wbc) or\n"
      "config/planner.yaml (mft-planner) while the stack runs, judged by that file's strict loader; a lockstep stack\n"
      "takes it at a stated simulated time only (--at), a realtime one at the next tick without --at\n"
      "(docs/live-tuning.md). Several --set: one change each, in order; the exit status is the worst.\n"
      "Exit status: 0 accepted (applied, or scheduled by the stack); 1 rejected by the stack (the reason is\n"
      "printed); 2 usage, input or DDS set-up error; 3 no stack answered on the domain within --timeout (no\n"
      "reader matched); 4 the readers did not acknowledge the command within --timeout; 5 no verdict within\n"
      "--verdict-timeout.");
  cli.option("domain", "DDS domain id of the stack (0..232)", "0");
  cli.option("mode", "stand | step_in_place | walk (an operator command)");
  cli.option("height", "base height command [m] (the planner accepts its reachable range)", "0.42");
  cli.option("speed", "average sagittal speed command [m/s]", "0.0");
  cli.option("push", "sagittal impulse on the torso [N s], + forward (a disturbance)");
  cli.option("at", "apply the push, or the --set changes, at this simulated time [s] (0: now / the next tick)", "0");
  cli.option("at-liftoff", "apply the push at the next lift-off of this leg: right | left");
  cli.option("set", "FILE.KEY=VALUE: change a tunable key of config/FILE.yaml (wbc or planner) while the stack runs, "
             "e.g. wbc.weights.slack=1e5 or wbc.gains.swing_foot.kp=[300,300] (repeatable)");
  cli.option("seq", "sequence number of the command, echoed by its verdict (default: from the clock and pid)");
  cli.option("timeout", "seconds to wait for a reader of the stack to match, and again for the acknowledgement", "5");
  cli.option("verdict-timeout", "seconds to wait for the stack's verdict once the command is written", "10");
  cli.flag("accepted-only", "return at the first acceptance (scheduled) instead of waiting until it is applied");
  cli.option("profiles", "DDS QoS profile file",
             mft::config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES));
  cli.option("secure", "DDS Security: the directory made by scripts/make-security.sh (secured stacks)");
  cli.option("identity", "with --secure: the identity to use", "cmd");
  cli.flag("json", "print one JSON object with the command, the verdicts and the result (also on failure)");
  cli.parse(argc, argv);

  const bool has_cmd = cli.isSet("mode"), has_push = cli.isSet("push");
  if (cli.isSet("set")) {
    if (has_cmd || has_push || cli.isSet("at-liftoff"))
      cli.fail("--set goes alone (with --at), not with --mode, --push or --at-liftoff");
    return runSet(cli);
  }
  if (has_cmd == has_push) cli.fail("give either --mode (an operator command), --push (a disturbance) or --set (a live change)");
  if (has_cmd && (cli.isSet("at") || cli.isSet("at-liftoff"))) cli.fail("--at and --at-liftoff go with --push");
  if (has_push && (cli.isSet("height") || cli.isSet("speed"))) cli.fail("--height and --speed go with --mode");
  if (cli.isSet("at") && cli.isSet("at-liftoff")) cli.fail("give --at or --at-liftoff, not both");
  const int domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  // Unique across processes started in the same millisecond: the pid in the low 16 bits.
  const auto seq = cli.isSet("seq")
                       ? static_cast<std::uint64_t>(cli.getInt("seq", 0, 1L << 62))
                       : (static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch() /
                                                     std::chrono::milliseconds(1))
                          << 16) | (static_cast<std::uint64_t>(getpid()) & 0xffffu);
  const double timeout_s = cli.getDouble("timeout", 0.1, 600);
  const double verdict_timeout_s = cli.getDouble("verdict-timeout", 0.1, 3600);
  const auto timeout = std::chrono::milliseconds(static_cast<long>(timeout_s * 1000));
  const bool json = cli.isSet("json");
  const bool accepted_only = cli.isSet("accepted-only");

  // The command, and how it is described in the output.
  msg::OperatorCommand command;
  msg::Disturbance push;
  std::string topic, answerer, what_text;
  std::function<void(config::JsonWriter&)> write_what;  // the command's fields in the JSON
  if (has_cmd) {
    const std::string mode = cli.get("mode");
    if (mode == "stand") command.mode(msg::LOCOMOTION_STAND);
    else if (mode == "step_in_place") command.mode(msg::LOCOMOTION_STEP_IN_PLACE);
    else if (mode == "walk") command.mode(msg::LOCOMOTION_WALK);
    else cli.fail("--mode: unknown mode '" + mode + "' (stand, step_in_place or walk)");
    command.seq(seq);
    command.z_cmd(cli.getDouble("height", -100.0, 100.0));
    command.v_cmd(cli.getDouble("speed", -100.0, 100.0));
    topic = "OperatorCommand";
    answerer = "mft-planner";
    write_what = [mode, &command](config::JsonWriter& w) {
      w.field("mode", mode).field("z_cmd", command.z_cmd(), 6).field("v_cmd", command.v_cmd(), 6);
    };
    what_text = mode + ", height " + fmt(command.z_cmd(), 3) + " m, speed " + fmt(command.v_cmd(), 3) + " m/s";
  } else {
    push.seq(seq);
    push.impulse(cli.getDouble("push", -1e4, 1e4));
    push.time_s(cli.getDouble("at", 0.0, 1e6));
    push.trigger(msg::TRIGGER_AT_TIME);
    push.leg(-1);
    if (cli.isSet("at-liftoff")) {
      const std::string leg = cli.get("at-liftoff");
      if (leg != "right" && leg != "left") cli.fail("--at-liftoff: expected right or left");
      push.trigger(msg::TRIGGER_AT_NEXT_LIFTOFF);
      push.leg(static_cast<std::int16_t>(leg == "right" ? 0 : 1));
    }
    topic = "Disturbance";
    answerer = "mft-sim";
    const bool liftoff = push.trigger() == msg::TRIGGER_AT_NEXT_LIFTOFF;
    write_what = [liftoff, &push](config::JsonWriter& w) {
      w.field("impulse_Ns", push.impulse(), 6).field("trigger", liftoff ? "at_next_liftoff" : "at_time");
      w.field("time_s", push.time_s(), 6).field("leg", push.leg());
    };
    what_text = fmt(push.impulse(), 3) + " N s " +
                (liftoff ? std::string("at the next ") + (push.leg() == 0 ? "right" : "left") + "-foot lift-off"
                         : cli.isSet("at") ? "at t = " + fmt(push.time_s(), 3) + " s" : std::string("now"));
  }
  const std::uint8_t source = has_cmd ? msg::COMMAND_SOURCE_PLANNER : msg::COMMAND_SOURCE_SIMULATOR;

  int matched = 0;
  bool acknowledged = false;
  std::vector<Verdict> verdicts;
  // One line on stderr (and the JSON object on stdout with --json) for every outcome.
  auto finish = [&](int code, const std::string& result, const std::string& error) {
    if (!error.empty()) std::fprintf(stderr, "mft-cmd: %s\n", error.c_str());
    if (json) {
      config::JsonWriter w;
      w.beginObject().field("command", topic).field("seq", seq).field("domain", domain);
      write_what(w);
      w.field("readers_matched", matched).field("acknowledged", acknowledged).field("answered_by", answerer);
      w.key("verdicts");
      writeVerdicts(w, verdicts);
      w.field("result", result).field("exit_code", code).field("error", error);
      std::printf("%s\n", w.endObject().str().c_str());
    }
    std::fflush(stdout);
    return code;
  };

  try {
    services::DdsParticipant participant(domain, cli.get("profiles"), "mft-cmd",
                                         services::SecurityOptions{cli.get("secure"), cli.get("identity")});
    std::mutex mutex;
    std::vector<Verdict> received;
    Clock::time_point written_at = Clock::now();
    // The verdict reader exists before the command is written; the stack's verdict writers are transient
    // local, so a verdict written before this reader matched them still arrives.
    services::TopicReader<msg::CommandVerdict, msg::CommandVerdictPubSubType> verdict_reader(
        participant, "CommandVerdict", "event_reader", [&](const msg::CommandVerdict& m) {
          if (m.seq() != seq || m.source() != source) return;  // another command's, or the other service's
          std::lock_guard<std::mutex> lock(mutex);
          Verdict v;
          v.verdict = m.verdict();
          v.tick = m.tick();
          v.stamp_ns = m.stamp_ns();
          v.reason.assign(m.reason().data(), strnlen(m.reason().data(), m.reason().size()));
          v.waited_s = std::chrono::duration<double>(Clock::now() - written_at).count();
          received.push_back(v);
        });
    std::unique_ptr<services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType>> command_writer;
    std::unique_ptr<services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType>> push_writer;
    if (has_cmd)
      command_writer = std::make_unique<services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType>>(
          participant, topic, "command_writer");
    else
      push_writer = std::make_unique<services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType>>(
          participant, topic, "command_writer");
    const auto readers = [&] { return has_cmd ? command_writer->matched() : push_writer->matched(); };

    if (!services::waitUntil([&] { return readers() > 0; }, timeout))
      return finish(kNoStack, "no_stack",
                    "no stack answered on domain " + std::to_string(domain) + " within " + fmt(timeout_s, -6) +
                        " s (no reader of " + topic + "; is the stack up on this domain?)");
    written_at = Clock::now();
    const bool written = has_cmd ? command_writer->write(command) : push_writer->write(push);
    if (!written) return finish(kUsage, "error", "the DDS writer refused the " + topic);
    acknowledged = has_cmd ? command_writer->waitForAcknowledgments(timeout) : push_writer->waitForAcknowledgments(timeout);
    matched = readers();
    if (!json) {
      std::printf("mft-cmd: %s seq %llu (%s) written to %d reader(s) on domain %d, %s\n", topic.c_str(),
                  static_cast<unsigned long long>(seq), what_text.c_str(), matched, domain,
                  acknowledged ? "acknowledged" : "NOT acknowledged yet");
      std::fflush(stdout);
    }

    // The verdicts: rejected, or scheduled then applied.
    const auto verdict_deadline = written_at + std::chrono::duration<double>(verdict_timeout_s);
    std::size_t shown = 0;
    bool scheduled = false;
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        verdicts = received;
      }
      for (; shown < verdicts.size(); ++shown) {
        const auto& v = verdicts[shown];
        if (v.verdict == msg::VERDICT_REJECTED)
          return finish(kRejected, "rejected", answerer + " rejected " + topic + " seq " + std::to_string(seq) + ": " + v.reason);
        if (!json)
          std::printf("%s: %s at tick %llu: %s\n", answerer.c_str(), services::verdictName(v.verdict),
                      static_cast<unsigned long long>(v.tick), v.reason.c_str());
        std::fflush(stdout);
        if (v.verdict == msg::VERDICT_APPLIED) return finish(kAccepted, "applied", "");
        if (v.verdict == msg::VERDICT_SCHEDULED) scheduled = true;
      }
      if (scheduled && accepted_only) return finish(kAccepted, "scheduled", "");
      if (Clock::now() > verdict_deadline) break;
      if (!acknowledged && !scheduled && Clock::now() > written_at + timeout)
        return finish(kNotAcknowledged, "not_acknowledged",
                      "the " + std::to_string(matched) + " reader(s) of " + topic + " on domain " + std::to_string(domain) +
                          " did not acknowledge seq " + std::to_string(seq) + " within " + fmt(timeout_s, -6) + " s");
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (scheduled) {
      if (!json)
        std::printf("mft-cmd: accepted by %s, not applied within %g s (it stays scheduled)\n", answerer.c_str(),
                    verdict_timeout_s);
      return finish(kAccepted, "scheduled", "");
    }
    return finish(kNoVerdict, "no_verdict",
                  "no verdict from " + answerer + " on " + topic + " seq " + std::to_string(seq) + " within " +
                      fmt(verdict_timeout_s, -6) + " s (" + (acknowledged ? "acknowledged" : "not acknowledged") + " by " +
                      std::to_string(matched) + " reader(s); is " + answerer + " running?)");
  } catch (const services::DdsError& e) {
    return finish(kUsage, "error", e.what());
  }
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-cmd", [&] { return toolMain(argc, argv); });
}
