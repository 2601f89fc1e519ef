#include "chain/actuator_driver.hpp"

namespace mft::chain {

ActuatorDriver::ActuatorDriver(double peak_torque_Nm, std::int64_t watchdog_timeout_ns)
    : peak_torque_(peak_torque_Nm), timeout_ns_(watchdog_timeout_ns), watchdog_(watchdog_timeout_ns) {
  episodes_.reserve(kEpisodes);
  missed_deadlines_ns_.reserve(kMissLog);
}

void ActuatorDriver::onPublished(std::uint64_t tick, std::int64_t now_ns) {
  published_tick_ = tick;
  publish_ns_[tick % kPublishRing] = now_ns;
}

InputVerdict ActuatorDriver::receive(const RawJointCommand& command, std::int64_t now_ns) {
  ++received_;
  const InputVerdict verdict = checkJointCommand(command.tau, command.mode, peak_torque_);
  if (verdict != InputVerdict::Ok) {
    ++refused_[static_cast<int>(verdict)];
    return verdict;
  }
  newest_.tick = command.tick;
  for (int i = 0; i < model::kNa; ++i) newest_.tau[i] = command.tau[static_cast<std::size_t>(i)];
  newest_.mode = command.mode == 1 ? model::CommandMode::Damping : model::CommandMode::Normal;
  watchdog_.onCommand(command.seq, now_ns);
  if (!has_command_ || command.tick > answered_tick_) answered_tick_ = command.tick;
  has_command_ = true;
  return verdict;
}

std::int64_t ActuatorDriver::latencyNs(std::uint64_t tick, std::int64_t now_ns) const {
  return tick == published_tick_ ? now_ns - publish_ns_[tick % kPublishRing] : -1;
}

// When the oldest published tick still without a command went out (kNothingWaiting: every tick is answered).
std::int64_t ActuatorDriver::waitingSinceNs() const {
  if (!has_command_ || answered_tick_ >= published_tick_) return CommandWatchdog::kNothingWaiting;
  const std::uint64_t oldest = answered_tick_ + 1;
  // Older than the ring: its oldest entry is the earliest publication still known (conservative).
  return publish_ns_[(published_tick_ - oldest >= kPublishRing ? published_tick_ + 1 : oldest) % kPublishRing];
}

ActuatorDriver::Hold ActuatorDriver::hold(std::int64_t now_ns, double sim_time_s) {
  Hold out;
  out.command = newest_;  // zero-order hold of the newest command
  const bool was_damping = damping_;
  const std::uint64_t misses_before = watchdog_.deadlineMisses();
  damping_ = has_command_ && watchdog_.damping(now_ns, waitingSinceNs());
  // One entry per counted miss (a recovery and a new miss between two periods count as two).
  out.new_miss = watchdog_.deadlineMisses() > misses_before;
  if (out.new_miss && missed_deadlines_ns_.size() < kMissLog) missed_deadlines_ns_.push_back(watchdog_.missedDeadlineNs());
  if (damping_ && !was_damping) {
    out.change = Change::DampingStarted;
    out.onset_late_ms = static_cast<double>(watchdog_.dampingSinceNs() - watchdog_.missedDeadlineNs()) * 1e-6;
    if (episodes_.size() < kEpisodes) episodes_.push_back({sim_time_s, out.onset_late_ms, -1.0});
    damping_onset_s_ = sim_time_s;
  }
  if (was_damping && !damping_) {
    out.change = Change::Resumed;
    out.damped_ms = (sim_time_s - damping_onset_s_) * 1e3;
    if (!episodes_.empty() && episodes_.back()[2] < 0) episodes_.back()[2] = (sim_time_s - episodes_.back()[0]) * 1e3;
  }
  if (!has_command_) {
    out.command.mode = model::CommandMode::Damping;  // start-up: the first command is still on its way
    ++startup_ticks_;
  } else if (damping_) {
    out.command.mode = model::CommandMode::Damping;
    ++damping_ticks_;
  }
  return out;
}

}  // namespace mft::chain
