#include "chain/estimator_node.hpp"

namespace mft::chain {

estimator::EstimatorConfig withScenarioMode(estimator::EstimatorConfig config, const std::string& scenario_estimator) {
  config.mode = scenario_estimator == "ground_truth" ? estimator::EstimatorMode::GroundTruth
                                                     : estimator::EstimatorMode::Kalman;
  return config;
}

const model::RobotStateEstimate& EstimatorNode::update(const model::SensorReadings& sensors,
                                                       const model::GroundTruthState* truth) {
  const bool need_truth = needsTruth();
  if (!initialized_) {
    estimator_.initialize(truth->q.head<3>(), truth->qd.head<3>(), sensors);
    initialized_ = true;
  }
  return estimator_.update(sensors, need_truth ? truth : nullptr);
}

}  // namespace mft::chain
