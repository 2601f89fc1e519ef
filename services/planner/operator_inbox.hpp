#pragma once
// mft-planner's operator commands from the OperatorCommand topic (mft-cmd, docs/guide/operator-commands.md). Each is
// judged on arrival against the planner's fixed limits and answered on CommandVerdict (rejected with the reason,
// or scheduled); a valid one waits here for the planner's next tick, which applies it before its plan (after the
// scenario's commands of that tick: the operator has the last word) and names the tick in an `applied` verdict.
// Fixed capacity, nothing allocated in the tick path; the caller holds its mutex around every call.
#include <array>
#include <cstdint>
#include <string>

#include "idl/msg_types.hpp"
#include "common/json_writer.hpp"
#include "planner/motion_planner.hpp"
#include "services/runtime/command_verdict.hpp"

namespace mft::services {

class OperatorInbox {
 public:
  explicit OperatorInbox(DdsParticipant& participant)
      : verdicts_(participant, "mft-planner", msg::COMMAND_SOURCE_PLANNER) {}

  // Judges `m`: a valid command waits for the next tick, a rejected one is logged and answered. `last_tick` (the
  // tick the planner answered last) is named in the verdict.
  void receive(const msg::OperatorCommand& m, const planner::CommandLimits& limits, std::uint64_t last_tick);
  // The tick boundary of tick `tick` (message stamp `stamp_ns`, simulated time `time_s`): gives every waiting
  // command to `planner` and answers each `applied`.
  void applyPending(planner::MotionPlanner& planner, std::uint64_t tick, std::uint64_t stamp_ns, double time_s);

  std::uint64_t rejected() const { return rejected_; }
  // {"received": N, "rejected": N, "applied": N, "waiting": N}
  void writeCounts(config::JsonWriter& w) const;  // {received, rejected, applied, waiting} as a value

 private:
  struct Pending {
    std::uint64_t seq;
    planner::OperatorCommand cmd;
  };
  VerdictPublisher verdicts_;
  std::array<Pending, 32> pending_{};
  std::size_t pending_count_ = 0;
  std::uint64_t received_ = 0, rejected_ = 0, applied_ = 0;
};

}  // namespace mft::services
