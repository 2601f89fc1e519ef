#pragma once
// mft-sim's run once its configuration is loaded: the endpoints (the JointCommand link, the Disturbance pushes,
// the gait phase, the recorder's flow control, the SensorData and GroundTruth writers), the wait for the
// controller chain, the loop that owns the clock (tick_exchange.hpp: lockstep or realtime), and the run summary.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "chain/sim_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/stall_probe.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/sim/command_link.hpp"
#include "services/sim/gait_link.hpp"
#include "services/sim/realtime_pacer.hpp"
#include "services/sim/recorder_flow.hpp"
#include "services/sim/tick_exchange.hpp"
#include "services/sim/topic_pushes.hpp"

namespace mft::services {

// What mft-sim loads before its endpoints exist: sim.yaml and the scenario's terrain.
struct SimSetup {
  sim::SimOptions options;
  sim::Terrain terrain;
};

class SimLoop {
 public:
  static void declareOptions(CommandLine& cli);  // beyond the service contract's
  static SimSetup load(const ServiceContext& ctx, const CommandLine& cli);  // exits 2 on a bad file
  // Builds the node (exits 2 when the scenario's initial pose cannot be built) and creates the endpoints.
  SimLoop(ServiceContext& ctx, const CommandLine& cli, const SimSetup& setup);
  // Waits for the chain, runs to the scenario's end (or a fall, a lockstep timeout, SIGINT/SIGTERM) and writes
  // the summary. Exit status: 0, or 3 on a timeout.
  int serve();

 private:
  using Clock = std::chrono::steady_clock;
  bool awaitChain();  // false (after saying why on stderr) when the chain did not connect or answer in time
  void run();         // the loop; error_ says why it stopped early
  bool step(std::uint64_t k, const model::ActuatorCommand& command);  // false: the run ends at a fall
  void reportProgress();
  int finish();
  void publish();  // the state of the current tick

  ServiceContext& ctx_;
  const CommandLine& cli_;
  const double control_period_s_;
  std::unique_ptr<chain::SimNode> node_;
  const std::chrono::duration<double> command_timeout_;
  const std::chrono::milliseconds resend_;
  const std::chrono::duration<double> start_timeout_;
  const std::int64_t watchdog_ns_;
  // publish: the tick's samples are written; command_in: its JointCommand reaches the listener; wake: the loop
  // holds it; stepped: the physics step is done.
  HopTrace hops_{"mft-sim", {"publish", "published", "command_in", "wake", "stepped"}};
  CommandLink link_;
  TopicPushes pushes_;
  std::unique_ptr<GaitLink> gait_;  // only for pushes at a gait phase
  RecorderFlow recorder_;
  TopicWriter<msg::SensorData, msg::SensorDataPubSubType> sensor_writer_;
  TopicWriter<msg::GroundTruth, msg::GroundTruthPubSubType> truth_writer_;
  msg::SensorData sensor_msg_;
  msg::GroundTruth truth_msg_;
  bool truth_first_;
  // Made once the chain answered (the clock starts then).
  std::unique_ptr<StallProbe> stall_probe_;
  std::optional<RealtimePacer> pacer_;
  std::optional<TickExchange> exchange_;
  std::uint64_t last_progress_tick_ = 0;
  std::string error_;
};

}  // namespace mft::services
