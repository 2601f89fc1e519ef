#pragma once
// The planner's gait phase for mft-sim's pushes at a gait phase (chain/push_schedule.hpp): a reader of the
// Reference topic (step index, phase, stance leg per tick), made only when the scenario has such a push, so a
// run without one is the stack as before. In lockstep the planner wrote Reference(k) before the WBC answered
// tick k, so once JointCommand(k) is here the sample for k is in its slot (chain channel) or on its way (DDS):
// forTick() polls for it and waits a bounded time.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>

#include "chain/push_schedule.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::services {

class GaitLink {
 public:
  explicit GaitLink(ServiceContext& ctx);
  // The planner's phase at tick k: waits up to `timeout` for Reference(k) (lockstep); realtime takes the newest.
  // Unknown (known false) when none came; counted in misses().
  chain::GaitPhase forTick(std::uint64_t k, std::chrono::milliseconds timeout);
  std::uint64_t misses() const { return misses_; }

 private:
  void onReference(const msg::Reference& m);

  bool lockstep_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  bool have_ = false;
  std::uint64_t tick_ = 0;
  chain::GaitPhase newest_;
  std::uint64_t misses_ = 0;
  TopicReader<msg::Reference, msg::ReferencePubSubType> reader_;
};

// A GaitLink when `scenario` has a push at a gait phase, else none.
std::unique_ptr<GaitLink> makeGaitLink(ServiceContext& ctx, const chain::Scenario& scenario);

}  // namespace mft::services
