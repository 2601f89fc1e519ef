#include "tools/mft-cmd/cmd_common.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "services/runtime/command_verdict.hpp"
#include "services/runtime/dds_participant.hpp"

namespace mft::cmd {

std::string fmt(double a, int digits) {
  char buf[64];
  if (digits >= 0) std::snprintf(buf, sizeof buf, "%.*f", digits, a);
  else std::snprintf(buf, sizeof buf, "%.*g", -digits, a);
  return buf;
}

Exchange exchangeOptions(const config::CommandLine& cli) {
  Exchange e;
  e.domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  e.timeout_s = cli.getDouble("timeout", 0.1, 600);
  e.verdict_timeout_s = cli.getDouble("verdict-timeout", 0.1, 3600);
  e.timeout = std::chrono::milliseconds(static_cast<long>(e.timeout_s * 1000));
  e.json = cli.isSet("json");
  e.accepted_only = cli.isSet("accepted-only");
  return e;
}

std::uint64_t commandSeq(const config::CommandLine& cli, std::uint64_t pid_mask, int pid_shift) {
  if (cli.isSet("seq")) return static_cast<std::uint64_t>(cli.getInt("seq", 0, 1L << 62));
  const auto ms = static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch() /
                                             std::chrono::milliseconds(1));
  return (ms << 16) | ((static_cast<std::uint64_t>(getpid()) & pid_mask) << pid_shift);
}

Verdict verdictOf(const msg::CommandVerdict& m, Clock::time_point written_at) {
  Verdict v;
  v.verdict = m.verdict();
  v.tick = m.tick();
  v.stamp_ns = m.stamp_ns();
  v.reason.assign(m.reason().data(), strnlen(m.reason().data(), m.reason().size()));
  v.waited_s = std::chrono::duration<double>(Clock::now() - written_at).count();
  return v;
}

void writeVerdicts(config::JsonWriter& w, const std::vector<Verdict>& verdicts) {
  w.beginArray();
  for (const auto& x : verdicts) {
    w.beginObject().field("verdict", services::verdictName(x.verdict)).field("tick", x.tick);
    w.fixedField("time_s", static_cast<double>(x.stamp_ns) * 1e-9, 4).field("reason", x.reason);
    w.fixedField("after_s", x.waited_s, 3).endObject();
  }
  w.endArray();
}

}  // namespace mft::cmd
