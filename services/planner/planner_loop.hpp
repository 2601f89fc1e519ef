#pragma once
// mft-planner's tick path: RobotState(k) -> the scenario's commands due, the operator's (operator_inbox.hpp) and
// the live changes due -> the plan -> Reference(k), under one mutex shared with the OperatorCommand reader.
#include <cstdint>
#include <mutex>
#include <string>

#include "chain/planner_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/planner/operator_inbox.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/service_main.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::services {

class PlannerLoop {
 public:
  static void declareOptions(CommandLine&) {}  // none beyond the service contract's
  // planner.yaml and the node it makes; exits 2 on a bad file.
  static TunableNode<chain::PlannerNode> load(const ServiceContext& ctx, const CommandLine& cli);
  // Creates the endpoints (the OperatorCommand reader and the live changes' too): from here on the node answers
  // every tick.
  PlannerLoop(ServiceContext& ctx, const CommandLine& cli,
              const TunableNode<chain::PlannerNode>& loaded);
  int serve() { return serveUntilShutdown(ctx_, *this); }  // the work runs in the DDS callbacks
  std::string summaryJson();                                 // the JSON the supervisor reads

 private:
  void onState(const msg::RobotState& m);
  void answer(const msg::RobotState& m);  // computes and writes Reference(m.tick())
  void reportScenarioCommand(const planner::OperatorCommand& cmd, const planner::CommandResult& result);

  ServiceContext& ctx_;
  chain::PlannerNode& node_;
  std::mutex mutex_;
  model::RobotStateEstimate state_;
  std::uint64_t scenario_rejected_ = 0;
  TickJoin join_{"mft-planner"};
  HopTrace hops_{"mft-planner", {"state_in", "write", "written"}};
  msg::Reference out_msg_;
  LatencyStats update_us_;
  OperatorInbox inbox_;
  LiveTuning<planner::PlannerTuning> tuning_;
  TopicWriter<msg::Reference, msg::ReferencePubSubType> writer_;
  TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader_;
  TopicReader<msg::OperatorCommand, msg::OperatorCommandPubSubType> command_reader_;
};

}  // namespace mft::services
