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
  sensors_ = sensors;
  sensors_.time_s = stampedTime(sensors.time_s);
  if (need_truth) {
    truth_ = *truth;
    truth_.time_s = stampedTime(truth->time_s);
  }
  if (!initialized_) {
    estimator_.initialize(truth_.q.head<3>(), truth_.qd.head<3>(), sensors_);
    initialized_ = true;
  }
  return estimator_.update(sensors_, need_truth ? &truth_ : nullptr);
}

}  // namespace mft::chain
