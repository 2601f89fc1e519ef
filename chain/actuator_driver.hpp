#pragma once
// The hardware boundary: what a robot's actuator driver does with the joint commands it receives, and what
// mft-sim does as one (docs/results/faults.md, docs/reference/architecture.md#clock-and-loop-modes). A real robot's bridge can
// reuse it as it is:
//  - a command that is not finite, beyond the actuators' peak torque or of an unknown mode is refused: it never
//    reaches an actuator and counts as missing (input_guard.hpp);
//  - realtime: when a published state has waited longer than the watchdog timeout for its command, the
//    actuators damp until commands resume (command_watchdog.hpp); before the first command they damp too.
// Pure logic on plain values and nanosecond times of a monotonic clock: no clock, thread or transport inside
// (the caller serializes the calls). Fixed capacities: nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "chain/command_watchdog.hpp"
#include "chain/input_guard.hpp"
#include "model/robot_io.hpp"

namespace mft::chain {

// A joint command as it arrives from the controller, not yet checked.
struct RawJointCommand {
  std::uint64_t tick = 0;  // the tick it answers
  std::uint64_t seq = 0;   // the controller's sequence number (gaps are lost commands)
  std::array<double, model::kNa> tau{};
  std::uint8_t mode = 0;   // 0 normal, 1 damping (msg::COMMAND_MODE_*)
};

// A damping episode: [onset sim time s, ms from the missed deadline to the onset, duration ms (-1: ongoing)].
using DampingEpisode = std::array<double, 3>;

class ActuatorDriver {
 public:
  static constexpr std::size_t kPublishRing = 1024;  // publication times kept, by tick % kPublishRing
  static constexpr std::size_t kEpisodes = 64;       // damping episodes kept for the summary
  static constexpr std::size_t kMissLog = 256;       // missed deadlines kept

  ActuatorDriver(double peak_torque_Nm, std::int64_t watchdog_timeout_ns);

  // The state of `tick` went out at `now_ns`: its command is awaited from then on.
  void onPublished(std::uint64_t tick, std::int64_t now_ns);
  // A command arrived at `now_ns`. Ok: it becomes the newest command; otherwise it is refused and counted.
  InputVerdict receive(const RawJointCommand& command, std::int64_t now_ns);

  // The newest accepted command, and whether it answers `tick` (lockstep waits for that).
  bool hasCommand() const { return has_command_; }
  const model::ActuatorCommand& newest() const { return newest_; }
  bool answers(std::uint64_t tick) const { return has_command_ && newest_.tick == tick; }
  std::uint64_t publishedTick() const { return published_tick_; }
  // From the publication of `tick` to `now_ns` if `tick` is the newest published tick, else -1.
  std::int64_t latencyNs(std::uint64_t tick, std::int64_t now_ns) const;

  // Realtime, once per control period at `now_ns` (sim time `sim_time_s`): the command held over the period,
  // the newest one or damping (before the first command, or while the watchdog has tripped).
  enum class Change { None, DampingStarted, Resumed };
  struct Hold {
    model::ActuatorCommand command;
    Change change = Change::None;
    bool new_miss = false;      // the watchdog counted a deadline miss in this period
    double onset_late_ms = 0;   // DampingStarted: from the missed deadline to the onset
    double damped_ms = 0;       // Resumed: the episode's length in sim time
  };
  Hold hold(std::int64_t now_ns, double sim_time_s);

  std::int64_t watchdogTimeoutNs() const { return timeout_ns_; }
  const CommandWatchdog& watchdog() const { return watchdog_; }
  std::uint64_t commandsReceived() const { return received_; }
  std::uint64_t refused(InputVerdict why) const { return refused_[static_cast<int>(why)]; }
  std::uint64_t dampingTicks() const { return damping_ticks_; }
  std::uint64_t startupTicks() const { return startup_ticks_; }
  // Episodes (the last one's duration -1 while it lasts) and every missed deadline's time, both capped.
  const std::vector<DampingEpisode>& episodes() const { return episodes_; }
  const std::vector<std::int64_t>& missedDeadlinesNs() const { return missed_deadlines_ns_; }

 private:
  std::int64_t waitingSinceNs() const;

  double peak_torque_;
  std::int64_t timeout_ns_;
  CommandWatchdog watchdog_;
  model::ActuatorCommand newest_;
  bool has_command_ = false, damping_ = false;
  std::uint64_t published_tick_ = 0, answered_tick_ = 0;
  std::array<std::int64_t, kPublishRing> publish_ns_{};
  double damping_onset_s_ = 0.0;
  std::uint64_t received_ = 0, damping_ticks_ = 0, startup_ticks_ = 0;
  std::array<std::uint64_t, 4> refused_{};  // by InputVerdict
  std::vector<DampingEpisode> episodes_;
  std::vector<std::int64_t> missed_deadlines_ns_;
};

}  // namespace mft::chain
