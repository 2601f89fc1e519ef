#include "services/planner/operator_inbox.hpp"

#include <cstdio>

#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"

namespace mft::services {

void OperatorInbox::receive(const msg::OperatorCommand& m, const planner::CommandLimits& limits,
                            std::uint64_t last_tick) {
  ++received_;
  planner::OperatorCommand cmd;
  fromMsg(m, &cmd);
  const auto check = planner::checkCommand(cmd, limits);
  const char* why = !check.accepted                      ? check.reason.c_str()
                    : m.mode() > msg::LOCOMOTION_WALK    ? "unknown locomotion mode (0 stand, 1 step_in_place, 2 walk)"
                    : !validInput(m)                     ? "not finite or implausible"
                    : pending_count_ == pending_.size() ? "too many commands waiting for the next tick"
                                                         : nullptr;
  if (why) {
    ++rejected_;
    std::fprintf(stderr, "mft-planner: operator command seq %llu rejected: %s\n",
                 static_cast<unsigned long long>(m.seq()), why);
    verdicts_.post(m.seq(), msg::VERDICT_REJECTED, last_tick, 0, "%s", why);
    return;
  }
  pending_[pending_count_++] = {m.seq(), cmd};
  verdicts_.post(m.seq(), msg::VERDICT_SCHEDULED, last_tick, 0,
                 "mode %s, height %.3f m, speed %.3f m/s accepted: in force from the next tick",
                 planner::toString(cmd.mode), cmd.z_cmd, cmd.v_cmd);
}

void OperatorInbox::applyPending(planner::MotionPlanner& planner, std::uint64_t tick, std::uint64_t stamp_ns,
                                 double time_s) {
  for (std::size_t i = 0; i < pending_count_; ++i) {
    const auto& p = pending_[i];
    planner.setCommand(p.cmd);  // judged valid on arrival against the same fixed limits
    ++applied_;
    verdicts_.post(p.seq, msg::VERDICT_APPLIED, tick, stamp_ns,
                   "mode %s, height %.3f m, speed %.3f m/s in force from tick %llu (t = %.3f s)",
                   planner::toString(p.cmd.mode), p.cmd.z_cmd, p.cmd.v_cmd, static_cast<unsigned long long>(tick),
                   time_s);
  }
  pending_count_ = 0;
}

void OperatorInbox::writeCounts(config::JsonWriter& w) const {
  w.beginObject().field("received", received_).field("rejected", rejected_).field("applied", applied_);
  w.field("waiting", pending_count_).endObject();
}

}  // namespace mft::services
