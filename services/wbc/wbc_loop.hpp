#pragma once
// mft-wbc's tick path: RobotState(k) and Reference(k) paired under one mutex (the two readers' callbacks may run
// on different DDS threads), the node's answer written as JointCommand(k) and WbcDiagnostics(k), live changes
// applied at the tick boundary, and the run figures for the summary.
#include <cstdint>
#include <mutex>
#include <string>

#include "chain/wbc_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/held_input.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/service_main.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/wbc/qp_dump.hpp"
#include "services/wbc/wbc_summary.hpp"

namespace mft::services {

class WbcLoop {
 public:
  static void declareOptions(CommandLine& cli);  // beyond the service contract's
  // wbc.yaml, the MFT polytope and the node they make; exits 2 on a bad file or a configuration the controller
  // refuses (an unknown controller).
  static TunableNode<chain::WbcNode> load(const ServiceContext& ctx, const CommandLine& cli);
  // Creates the endpoints: from here on the node answers every tick.
  WbcLoop(ServiceContext& ctx, const CommandLine& cli, const TunableNode<chain::WbcNode>& loaded);
  int serve() { return serveUntilShutdown(ctx_, *this); }  // the work runs in the DDS callbacks
  std::string summaryJson();                                 // the JSON the supervisor reads

 private:
  void process(bool state_arrived);  // under mutex_
  void answer();                     // computes and writes the held state's tick
  void onState(const msg::RobotState& m);
  void onReference(const msg::Reference& m);

  ServiceContext& ctx_;
  chain::WbcNode& node_;
  const QpDump qp_dump_;
  std::mutex mutex_;
  HeldInput<model::RobotStateEstimate> state_;
  HeldInput<wbc::WbcReference> reference_;
  std::uint64_t seq_ = 0;
  TickJoin join_{"mft-wbc"};
  HopTrace hops_{"mft-wbc", {"state_in", "reference_in", "compute", "write", "written"}};
  WbcFigures figures_;
  msg::JointCommand command_msg_;
  msg::WbcDiagnostics diag_msg_;
  TopicWriter<msg::JointCommand, msg::JointCommandPubSubType> command_writer_;
  TopicWriter<msg::WbcDiagnostics, msg::WbcDiagnosticsPubSubType> diag_writer_;
  LiveTuning<wbc::WbcTuning> tuning_;
  const std::uint64_t max_age_;  // realtime: the oldest Reference that may answer a RobotState [ticks]
  TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader_;
  TopicReader<msg::Reference, msg::ReferencePubSubType> reference_reader_;
};

}  // namespace mft::services
