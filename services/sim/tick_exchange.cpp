#include "services/sim/tick_exchange.hpp"

#include <cstdio>

#include "services/runtime/process.hpp"

namespace mft::services {

using Clock = std::chrono::steady_clock;

TickExchange::TickExchange(bool lockstep, const Timeouts& timeouts, CommandLink& link, RecorderFlow& recorder,
                           RealtimePacer& pacer, HopTrace& hops)
    : lockstep_(lockstep), timeouts_(timeouts), link_(link), recorder_(recorder), pacer_(pacer), hops_(hops) {
  wall_start_ = Clock::now();
  pacer_.start(wall_start_);
}

bool TickExchange::commandFor(std::uint64_t k, double now_s, const std::function<void()>& publish,
                              model::ActuatorCommand* out, std::string* error) {
  if (!recorder_.awaitWindow(k, timeouts_.command, error)) return false;
  publish();
  if (lockstep_) return lockstep(k, publish, out, error);
  realtime(now_s, out);
  return true;
}

bool TickExchange::lockstep(std::uint64_t k, const std::function<void()>& publish, model::ActuatorCommand* out,
                            std::string* error) {
  const auto timeout = k == 0 ? timeouts_.start : timeouts_.command;
  const bool answered = link_.awaitAnswer(
      k, timeout, k == 0 ? std::chrono::milliseconds(100) : timeouts_.resend,
      [&] {
        publish();
        if (k > 0) ++resends_;
      },
      [&] { return k > 0 || recorder_.heardLocked(); });
  if (shutdownRequested()) return false;
  if (!answered) {
    char buf[200];
    if (link_.answers(k))
      std::snprintf(buf, sizeof buf, "timeout: mft-record did not receive every topic within %.1f s (is it running?)",
                    timeouts_.start.count());
    else
      std::snprintf(buf, sizeof buf, "timeout: no JointCommand for tick %llu within %.1f s (is mft-wbc running?)",
                    static_cast<unsigned long long>(k), timeout.count());
    *error = buf;
    return false;
  }
  *out = link_.newest();
  hops_.mark(3, k);
  if (k == 0) {
    const auto answered_at = Clock::now();
    start_wait_s_ = std::chrono::duration<double>(answered_at - wall_start_).count();
    wall_start_ = answered_at;
    std::printf("mft-sim: the chain answered tick 0: the clock starts\n");  // the supervisor's `up` waits for it
    std::fflush(stdout);
  }
  return true;
}

void TickExchange::realtime(double now_s, model::ActuatorCommand* out) {
  pacer_.sleep();
  const auto hold = link_.hold(now_s);
  *out = hold.command;
  if (hold.new_miss) pacer_.noteMiss();
  if (hold.change == chain::ActuatorDriver::Change::DampingStarted) {
    detection_ms_.add(hold.onset_late_ms);
    std::printf("mft-sim: a tick waited %.1f ms for its command: actuators damping (t = %.3f s)\n",
                static_cast<double>(link_.driver().watchdogTimeoutNs()) * 1e-6 + hold.onset_late_ms, now_s);
    std::fflush(stdout);
  } else if (hold.change == chain::ActuatorDriver::Change::Resumed) {
    // The counterpart of the onset line: tests wait for it instead of sleeping until commands flow again.
    std::printf("mft-sim: commands resumed after %.1f ms of damping (t = %.3f s)\n", hold.damped_ms, now_s);
    std::fflush(stdout);
  }
}

}  // namespace mft::services
