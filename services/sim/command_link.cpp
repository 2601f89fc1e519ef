#include "services/sim/command_link.hpp"

#include <cstdio>

#include "services/runtime/process.hpp"

namespace mft::services {

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

CommandLink::CommandLink(ServiceContext& ctx, HopTrace& hops, double peak_torque_Nm, std::int64_t watchdog_timeout_ns)
    : lockstep_(ctx.lockstep()),
      hops_(hops),
      driver_(peak_torque_Nm, watchdog_timeout_ns),
      reader_(ctx.reading("JointCommand"),
              [this](const msg::JointCommand& m) { onCommand(m); },
              ctx.lockstep() ? ChainSlotReader::Delivery::Polled : ChainSlotReader::Delivery::Woken) {}

void CommandLink::onCommand(const msg::JointCommand& m) {
  hops_.mark(2, m.tick());
  const std::int64_t t = steadyNowNs();
  chain::RawJointCommand raw;
  raw.tick = m.tick();
  raw.seq = m.seq();
  raw.tau = m.tau();
  raw.mode = m.mode();
  std::lock_guard<std::mutex> lock(mutex_);
  // A refused command never reaches the actuators: it counts as a missing one (the watchdog damps when only
  // such commands come).
  const auto verdict = driver_.receive(raw, t);
  if (verdict != chain::InputVerdict::Ok) {
    if (driver_.refused(verdict) == 1)
      std::printf("mft-sim: refused a JointCommand (tick %llu): %s\n", static_cast<unsigned long long>(m.tick()),
                  chain::toString(verdict));
    return;
  }
  const std::int64_t latency_ns = driver_.latencyNs(m.tick(), t);
  if (!lockstep_ && latency_ns >= 0) latency_us_.add(static_cast<double>(latency_ns) * 1e-3);
  arrived_.notify_all();
}

void CommandLink::published(std::uint64_t tick) {
  std::lock_guard<std::mutex> lock(mutex_);
  driver_.onPublished(tick, steadyNowNs());
}

bool CommandLink::awaitAnswer(std::uint64_t tick, std::chrono::duration<double> timeout,
                              std::chrono::milliseconds resend, const std::function<void()>& republish,
                              const std::function<bool()>& also) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const auto answered = [&] { return driver_.answers(tick) && also(); };
  while (!answered() && !shutdownRequested()) {
    if (std::chrono::steady_clock::now() > deadline) break;
    if (reader_.viaChainChannel() && !driver_.answers(tick)) {  // this thread takes the command: no hand-off
      lock.unlock();
      const bool arrived = reader_.awaitChannel(resend);  // onCommand() runs here when it does
      if (!arrived) republish();
      lock.lock();
      continue;
    }
    if (arrived_.wait_for(lock, resend) == std::cv_status::timeout) {
      lock.unlock();
      republish();
      lock.lock();
    }
  }
  return answered();
}

bool CommandLink::awaitFirst(std::chrono::steady_clock::time_point deadline, std::chrono::milliseconds resend,
                             const std::function<void()>& republish) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!driver_.hasCommand() && !shutdownRequested() && std::chrono::steady_clock::now() < deadline) {
    lock.unlock();
    republish();
    lock.lock();
    arrived_.wait_for(lock, resend);
  }
  return driver_.hasCommand();
}

chain::ActuatorDriver::Hold CommandLink::hold(double sim_time_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  return driver_.hold(steadyNowNs(), sim_time_s);
}

model::ActuatorCommand CommandLink::newest() {
  std::lock_guard<std::mutex> lock(mutex_);
  return driver_.newest();
}

bool CommandLink::answers(std::uint64_t tick) {
  std::lock_guard<std::mutex> lock(mutex_);
  return driver_.answers(tick);
}

}  // namespace mft::services
