#pragma once
// The estimator stage of the chain: sensors(k) [+ truth(k)] -> estimate(k). The filter starts from the
// simulator's pose at the first tick (the robot is placed at a known standing pose), so that tick needs the
// truth; in the scenario's ground_truth mode every tick passes the simulator's truth through (to tell
// controller problems from estimator problems).
//
// Time enters the chain here, on the whole-nanosecond stamp every message of the stack carries (stampedTime):
// the in-process loop then computes with the same times as the DDS stack, bit for bit.
#include <cstdint>
#include <string>

#include "estimator/state_estimator.hpp"

namespace mft::chain {

// `time_s` as the stack's messages carry it: rounded to whole nanoseconds (services/runtime/convert.hpp's
// toStampNs / fromStampNs). Idempotent: a time read from a stamp comes back unchanged.
inline double stampedTime(double time_s) {
  return static_cast<double>(static_cast<std::uint64_t>(time_s * 1e9 + 0.5)) * 1e-9;
}

// The estimator configuration with the scenario's `estimator` key ("kalman" | "ground_truth") applied.
estimator::EstimatorConfig withScenarioMode(estimator::EstimatorConfig config, const std::string& scenario_estimator);

class EstimatorNode {
 public:
  EstimatorNode(const estimator::EstimatorConfig& config, const model::RobotDescription& robot)
      : mode_(config.mode), estimator_(config, robot) {}

  // Whether the next update needs the truth of the same tick.
  bool needsTruth() const { return !initialized_ || mode_ == estimator::EstimatorMode::GroundTruth; }
  // `truth` must be the same tick's when needsTruth(); otherwise it is not used (may be null). Their times are
  // taken on the nanosecond stamp (stampedTime).
  const model::RobotStateEstimate& update(const model::SensorReadings& sensors, const model::GroundTruthState* truth);
  // A new clock (a restarted simulator): the next update starts the filter again from the truth.
  void restart() { initialized_ = false; }
  const estimator::StateEstimator& estimator() const { return estimator_; }

 private:
  estimator::EstimatorMode mode_;
  estimator::StateEstimator estimator_;
  bool initialized_ = false;
  model::SensorReadings sensors_;
  model::GroundTruthState truth_;
};

}  // namespace mft::chain
