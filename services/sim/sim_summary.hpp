#pragma once
// mft-sim's run summary (the JSON the supervisor reads): the run monitor's verdict and tracking figures, the
// actuator driver's counters and damping episodes, the recorder's flow control, the operator's pushes, the
// push-recovery record and the realtime timing (with each deadline miss judged against the CPU stall probe).
#include <cstdint>
#include <string>

#include "chain/sim_node.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/stall_probe.hpp"
#include "services/sim/command_link.hpp"
#include "services/sim/realtime_pacer.hpp"
#include "services/sim/recorder_flow.hpp"
#include "services/sim/topic_pushes.hpp"

namespace mft::services {

struct SimRun {
  const ServiceContext& ctx;
  const chain::SimNode& node;
  CommandLink& link;
  const RecorderFlow& recorder;
  const TopicPushes& pushes;
  const RealtimePacer& pacer;
  const StallProbe* stall_probe;     // null when off
  const LatencyStats& detection_ms;  // from each missed deadline to the onset of damping
  const std::string& error;
  double wall_s, start_wait_s;
  std::uint64_t resends;
  bool recorder_complete;
};

std::string simSummaryJson(const SimRun& run);

}  // namespace mft::services
