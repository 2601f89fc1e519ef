#pragma once
// What mft-cmd's two exchanges share (a command or push: send_command; live changes: live_set): the exit
// statuses, the options every exchange reads, the stack's verdicts as received and as JSON.
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "common/command_line.hpp"
#include "common/json_writer.hpp"
#include "idl/msg_types.hpp"
#include "services/runtime/dds_participant.hpp"

namespace mft::cmd {

using Clock = std::chrono::steady_clock;

// Exit statuses (also in --help). kNotDelivered: the verdict is as reported, but a service that reads the topic
// (the recorder, say) did not acknowledge the request (delivery.hpp).
constexpr int kAccepted = 0, kRejected = 1, kUsage = 2, kNoStack = 3, kNotAcknowledged = 4, kNoVerdict = 5,
              kNotDelivered = 6;

// A number with `digits` decimals (fixed) or significant digits (general, digits < 0 means -digits).
std::string fmt(double a, int digits);

// The options both exchanges read: where the stack is, how long to wait, how to report.
struct Exchange {
  int domain = 0;
  double timeout_s = 5, verdict_timeout_s = 10;
  std::chrono::milliseconds timeout{5000};
  bool json = false, accepted_only = false;
};
Exchange exchangeOptions(const config::CommandLine& cli);

// --seq, or one from the clock (milliseconds << 16) and this process's pid in the low 16 bits, so processes
// started in the same millisecond differ. `pid_shift` leaves the lowest bits free for consecutive seqs (--set).
std::uint64_t commandSeq(const config::CommandLine& cli, std::uint64_t pid_mask, int pid_shift);

struct Verdict {
  std::uint8_t verdict = 0;
  std::uint64_t tick = 0, stamp_ns = 0;
  std::string reason;
  double waited_s = 0;  // since the command was written
};
Verdict verdictOf(const msg::CommandVerdict& m, Clock::time_point written_at);

// exchange(participant) on the stack's domain with the --profiles, --secure and --identity options; a DDS set-up
// error ends as finish(kUsage, "error", its message). The participant keeps the participants it discovers: the
// delivery check (delivery.hpp) needs to know who should read a request.
template <typename Exchange, typename Finish>
int withParticipant(const config::CommandLine& cli, int domain, Exchange exchange, Finish finish) {
  try {
    services::DdsParticipant participant(domain, cli.get("profiles"), "mft-cmd",
                                         services::SecurityOptions{cli.get("secure"), cli.get("identity")},
                                         services::ReceiveTuning{}, services::DiscoveryOptions{"", true});
    return exchange(participant);
  } catch (const services::DdsError& e) {
    return finish(kUsage, "error", e.what());
  }
}

// The verdicts as a JSON array.
void writeVerdicts(config::JsonWriter& w, const std::vector<Verdict>& verdicts);

}  // namespace mft::cmd
