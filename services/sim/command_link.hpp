#pragma once
// mft-sim's side of the JointCommand topic: commands arrive on a DDS thread and go through the actuator driver
// (chain/actuator_driver.hpp: refusal of bad commands, the realtime watchdog and damping) under one mutex; the
// simulator's loop waits on it (lockstep) or samples the held command once a period (realtime). On the lockstep
// chain channel the loop thread itself sleeps on the topic's slot and takes the command (no thread hand-off).
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>

#include "chain/actuator_driver.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::services {

std::int64_t steadyNowNs();

class CommandLink {
 public:
  CommandLink(ServiceContext& ctx, HopTrace& hops, double peak_torque_Nm, std::int64_t watchdog_timeout_ns);

  // The loop published the state of `tick` now.
  void published(std::uint64_t tick);
  // Lockstep: waits until the command answering `tick` is here and `also()` holds (both under the mutex),
  // calling republish() every `resend` without an answer (it must not take the mutex). False at the timeout
  // or on shutdown.
  bool awaitAnswer(std::uint64_t tick, std::chrono::duration<double> timeout, std::chrono::milliseconds resend,
                   const std::function<void()>& republish, const std::function<bool()>& also);
  // Realtime start: publishes every `resend` until a first command arrives or `deadline` passes.
  bool awaitFirst(std::chrono::steady_clock::time_point deadline, std::chrono::milliseconds resend,
                  const std::function<void()>& republish);
  // Realtime, once a period: the command to hold (the driver's decision at this instant).
  chain::ActuatorDriver::Hold hold(double sim_time_s);
  model::ActuatorCommand newest();
  bool answers(std::uint64_t tick);  // the newest command answers `tick`

  // The mutex guards the driver and whatever else the loop shares with DDS threads (recorder progress, pushes).
  std::mutex& mutex() { return mutex_; }
  std::condition_variable& arrived() { return arrived_; }
  const chain::ActuatorDriver& driver() const { return driver_; }  // under mutex()
  const LatencyStats& latencyUs() const { return latency_us_; }
  int matchedWriters() const { return reader_.matched(); }
  DeadlineCounts deadlineCounts() const { return reader_.deadlineCounts(); }

 private:
  void onCommand(const msg::JointCommand& m);

  bool lockstep_;
  HopTrace& hops_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  chain::ActuatorDriver driver_;
  LatencyStats latency_us_;  // realtime: from SensorData(k) leaving to JointCommand(k) arriving
  TopicReader<msg::JointCommand, msg::JointCommandPubSubType> reader_;
};

}  // namespace mft::services
