#pragma once
// mft-estimator's tick path: tick k once SensorData(k) is here, and GroundTruth(k) when the node needs it (the
// scenario's ground_truth mode), under one mutex (the two readers' callbacks may run on different DDS threads);
// the node's estimate written as RobotState(k).
#include <mutex>
#include <string>

#include "chain/estimator_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/held_input.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/service_main.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::services {

class EstimatorLoop {
 public:
  static void declareOptions(CommandLine&) {}  // none beyond the service contract's
  static estimator::EstimatorConfig load(const ServiceContext& ctx, const CommandLine& cli);  // exits 2 on a bad file
  // Makes the node from `config` (estimator.yaml) and the scenario's mode, and creates the endpoints.
  EstimatorLoop(ServiceContext& ctx, const CommandLine& cli, const estimator::EstimatorConfig& config);
  int serve() { return serveUntilShutdown(ctx_, *this); }  // the work runs in the DDS callbacks
  std::string summaryJson();                                 // the JSON the supervisor reads

 private:
  void onTruth(const msg::GroundTruth& m);
  void onSensors(const msg::SensorData& m);
  void process(bool sensor_arrived);  // under mutex_

  ServiceContext& ctx_;
  chain::EstimatorNode node_;
  std::mutex mutex_;
  HeldInput<model::SensorReadings> sensors_;
  HeldInput<model::GroundTruthState> truth_;
  TickJoin join_{"mft-estimator"};
  HopTrace hops_{"mft-estimator", {"sensor_in", "write", "written"}};
  msg::RobotState out_msg_;
  LatencyStats update_us_;
  TopicWriter<msg::RobotState, msg::RobotStatePubSubType> writer_;
  TopicReader<msg::GroundTruth, msg::GroundTruthPubSubType> truth_reader_;
  TopicReader<msg::SensorData, msg::SensorDataPubSubType> sensor_reader_;
};

}  // namespace mft::services
