#pragma once
// The simulator's actuator-driver watchdog in realtime mode (docs/reference/architecture.md#clock-and-loop-modes): when a published tick
// has waited longer than the timeout for its joint command, the actuators go into damping until commands
// resume. The wait is measured from the tick's publication, not from the last command's arrival: a simulator
// that wakes up late and catches up by stepping back to back must not book its own lateness as a controller
// miss (it did: every wake-up more than ~2.4 ms late counted), and a controller that answers every tick but
// too late is caught (it was not). Also counts sequence-number gaps (lost or skipped commands). Times in
// nanoseconds of a monotonic clock; pure logic, no clock or DDS inside, so it is unit-tested directly.
#include <cstdint>

namespace mft::chain {

class CommandWatchdog {
 public:
  explicit CommandWatchdog(std::int64_t timeout_ns) : timeout_ns_(timeout_ns) {}

  // A command with sequence number `seq` arrived at `now_ns`.
  void onCommand(std::uint64_t seq, std::int64_t now_ns) {
    if (has_command_ && seq > last_seq_ + 1) lost_commands_ += seq - last_seq_ - 1;
    if (!has_command_ || seq > last_seq_) last_seq_ = seq;
    has_command_ = true;
    last_arrival_ns_ = now_ns;
    if (damping_) {
      damping_ = false;
      ++recoveries_;
    }
  }

  // Evaluated once per control period with the publication time of the oldest tick still waiting for its
  // command (kNothingWaiting when every published tick is answered); true while the actuators must damp.
  static constexpr std::int64_t kNothingWaiting = -1;
  bool damping(std::int64_t now_ns, std::int64_t waiting_since_ns) {
    if (!has_command_) return false;  // before the first command the simulator waits for the controller
    if (!damping_ && waiting_since_ns != kNothingWaiting && now_ns - waiting_since_ns > timeout_ns_) {
      damping_ = true;
      ++deadline_misses_;
      damping_since_ns_ = now_ns;
      missed_deadline_ns_ = waiting_since_ns + timeout_ns_;
    }
    return damping_;
  }

  std::uint64_t deadlineMisses() const { return deadline_misses_; }
  std::uint64_t lostCommands() const { return lost_commands_; }
  std::uint64_t recoveries() const { return recoveries_; }
  std::int64_t dampingSinceNs() const { return damping_since_ns_; }
  std::int64_t missedDeadlineNs() const { return missed_deadline_ns_; }  // of the latest miss
  std::int64_t lastArrivalNs() const { return last_arrival_ns_; }

 private:
  std::int64_t timeout_ns_;
  bool has_command_ = false;
  bool damping_ = false;
  std::uint64_t last_seq_ = 0;
  std::int64_t last_arrival_ns_ = 0;
  std::int64_t damping_since_ns_ = 0;
  std::int64_t missed_deadline_ns_ = 0;
  std::uint64_t deadline_misses_ = 0, lost_commands_ = 0, recoveries_ = 0;
};

}  // namespace mft::chain
