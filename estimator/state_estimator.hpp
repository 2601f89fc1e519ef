#pragma once
// The floating-base state estimator (Fig. 2 "state estimator"): RobotStateEstimate from SensorReadings.
//   Kalman mode: PitchFilter (gyro + accelerometer tilt) -> BaseKalmanFilter (IMU + stance-leg kinematics)
//                with contact from ContactDetector; leg q, qd straight from the encoders.
//   GroundTruth mode: the simulator's GroundTruthState passed through unchanged (q, qd, tick, time), contact
//                from the true normal forces; tells a controller problem from an estimator problem.
#include <Eigen/Core>

#include "estimator/base_kalman_filter.hpp"
#include "estimator/contact_detector.hpp"
#include "estimator/estimator_config.hpp"
#include "estimator/leg_kinematics.hpp"
#include "estimator/pitch_filter.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"

namespace mft::estimator {

class StateEstimator {
 public:
  StateEstimator(const EstimatorConfig& config, const model::RobotDescription& robot);

  EstimatorMode mode() const { return config_.mode; }

  // Dispatches on the configured mode; GroundTruth mode needs `truth` (std::invalid_argument otherwise).
  const model::RobotStateEstimate& update(const model::SensorReadings& readings,
                                          const model::GroundTruthState* truth = nullptr);

  // Kalman mode. The first call initializes itself unless initialize() was called: pitch from the
  // accelerometer (robot assumed at rest), x = 0, z from the lowest contact foot at the ground height.
  const model::RobotStateEstimate& updateKalman(const model::SensorReadings& readings);
  // The bypass, usable in either mode.
  const model::RobotStateEstimate& updateGroundTruth(const model::GroundTruthState& truth);

  // Starts the filter from a known base state [x, z, pitch] and rate, with the legs from `readings`.
  void initialize(const Eigen::Vector3d& base_pose, const Eigen::Vector3d& base_rate,
                  const model::SensorReadings& readings);
  void reset() { initialized_ = false; }

  const model::RobotStateEstimate& estimate() const { return out_; }
  const BaseKalmanFilter& filter() const { return kf_; }
  const PitchFilter& pitchFilter() const { return pitch_; }
  const ContactDetector& contactDetector() const { return contact_; }
  const EstimatorConfig& config() const { return config_; }

 private:
  void legKinematics(const model::SensorReadings& s);
  void fillOutput(const model::SensorReadings& s);

  EstimatorConfig config_;
  model::FiveBarGeometry geometry_;
  double gravity_;
  Eigen::Vector2d imu_in_base_;
  PitchFilter pitch_;
  BaseKalmanFilter kf_;
  ContactDetector contact_;
  bool initialized_ = false;
  double last_time_ = 0.0;
  Eigen::Vector2d accel_est_{0, 0};  // low-passed IMU acceleration (world) for the tilt compensation
  std::array<FootInBase, model::kNumLegs> feet_{};
  std::array<bool, model::kNumLegs> stance_{};
  model::RobotStateEstimate out_;
};

}  // namespace mft::estimator
