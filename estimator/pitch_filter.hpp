#pragma once
// Pitch from gyro integration with a complementary (PI) correction toward the accelerometer tilt:
//   pitch' = gyro - bias + k_p e,   bias' = -k_i e,   e = wrap(tilt - pitch),   k_p = 1 / time constant.
// The tilt is the angle between the measured specific force (body frame) and the world specific force
// a - g; a is the IMU acceleration estimated by the Kalman filter (or 0 without compensation). The
// correction is skipped when the magnitudes disagree by more than the gate (impacts, pushes).
#include <Eigen/Core>

#include "estimator/estimator_config.hpp"

namespace mft::estimator {

// Pitch for which R(pitch) * specific_force_body is parallel to accel_world - gravity_world.
double tiltFromSpecificForce(const Eigen::Vector2d& specific_force_body, const Eigen::Vector2d& accel_world,
                             double gravity);

class PitchFilter {
 public:
  PitchFilter(const PitchParams& params, double gravity) : params_(params), gravity_(gravity) {}

  void reset(double pitch, double gyro_bias = 0.0);
  void update(double gyro_rate, const Eigen::Vector2d& specific_force_body, const Eigen::Vector2d& accel_world,
              double dt);

  double pitch() const { return pitch_; }
  double rate() const { return rate_; }         // gyro - bias (the correction term is not a physical rate)
  double gyroBias() const { return bias_; }
  bool correctionUsed() const { return used_; }

 private:
  PitchParams params_;
  double gravity_;
  double pitch_ = 0.0, rate_ = 0.0, bias_ = 0.0;
  bool used_ = false;
};

}  // namespace mft::estimator
