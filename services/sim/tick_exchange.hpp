#pragma once
// How mft-sim gets the command for tick k after publishing its state (docs/reference/architecture.md#clock-and-loop-modes):
//  lockstep: waits for JointCommand(k), re-sending tick k while the answer is late (the chain is best effort: a
//            lost sample costs one re-send; every service answers a repeated tick with its cached answer); tick 0
//            of a recorded run is also held until the recorder receives every topic; the run's wall time starts
//            once tick 0 is answered (discovery is start-up, not loop speed);
//  realtime: sleeps to the next 1 kHz deadline and holds the actuator driver's command (damping while the
//            watchdog has tripped), logging the onset and the end of each damping episode.
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/sim/command_link.hpp"
#include "services/sim/realtime_pacer.hpp"
#include "services/sim/recorder_flow.hpp"

namespace mft::services {

class TickExchange {
 public:
  struct Timeouts {
    std::chrono::duration<double> command, start;  // lockstep: per tick, and for tick 0
    std::chrono::milliseconds resend;              // lockstep: re-send a tick this late
  };
  TickExchange(bool lockstep, const Timeouts& timeouts, CommandLink& link, RecorderFlow& recorder,
               RealtimePacer& pacer, HopTrace& hops);

  // The command for tick k (sim time `now_s`) once `publish` has sent its state; false with `error` (lockstep
  // timeouts) or on shutdown (error empty).
  bool commandFor(std::uint64_t k, double now_s, const std::function<void()>& publish, model::ActuatorCommand* out,
                  std::string* error);

  std::chrono::steady_clock::time_point wallStart() const { return wall_start_; }
  double startWaitSeconds() const { return start_wait_s_; }
  std::uint64_t resends() const { return resends_; }
  const LatencyStats& detectionMs() const { return detection_ms_; }

 private:
  bool lockstep(std::uint64_t k, const std::function<void()>& publish, model::ActuatorCommand* out, std::string* error);
  void realtime(double now_s, model::ActuatorCommand* out);

  bool lockstep_;
  Timeouts timeouts_;
  CommandLink& link_;
  RecorderFlow& recorder_;
  RealtimePacer& pacer_;
  HopTrace& hops_;
  std::chrono::steady_clock::time_point wall_start_;
  double start_wait_s_ = 0.0;
  std::uint64_t resends_ = 0;
  LatencyStats detection_ms_{10000};  // realtime: from each missed deadline to the onset of damping
};

}  // namespace mft::services
