#pragma once
// The simulator's actuator-driver watchdog in realtime mode (ARCHITECTURE.md section 3): when joint commands
// stop arriving for longer than the timeout, the actuators go into damping until commands resume. It also
// counts sequence-number gaps (lost or skipped commands) and every missed deadline. Times in nanoseconds of
// a monotonic clock; pure logic, no clock or DDS inside, so it is unit-tested directly.
#include <cstdint>

namespace mft::services {

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

  // Evaluated once per control period; returns true while the actuators must damp.
  bool damping(std::int64_t now_ns) {
    if (!has_command_) return false;  // before the first command the simulator waits for the controller
    if (!damping_ && now_ns - last_arrival_ns_ > timeout_ns_) {
      damping_ = true;
      ++deadline_misses_;
      damping_since_ns_ = now_ns;
    }
    return damping_;
  }

  std::uint64_t deadlineMisses() const { return deadline_misses_; }
  std::uint64_t lostCommands() const { return lost_commands_; }
  std::uint64_t recoveries() const { return recoveries_; }
  std::int64_t dampingSinceNs() const { return damping_since_ns_; }
  std::int64_t lastArrivalNs() const { return last_arrival_ns_; }

 private:
  std::int64_t timeout_ns_;
  bool has_command_ = false;
  bool damping_ = false;
  std::uint64_t last_seq_ = 0;
  std::int64_t last_arrival_ns_ = 0;
  std::int64_t damping_since_ns_ = 0;
  std::uint64_t deadline_misses_ = 0, lost_commands_ = 0, recoveries_ = 0;
};

}  // namespace mft::services
