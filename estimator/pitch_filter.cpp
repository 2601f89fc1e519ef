#include "estimator/pitch_filter.hpp"

#include <cmath>

#include "model/five_bar.hpp"

namespace mft::estimator {

double tiltFromSpecificForce(const Eigen::Vector2d& f_body, const Eigen::Vector2d& accel_world, double gravity) {
  const Eigen::Vector2d f_world(accel_world.x(), accel_world.y() + gravity);  // a - g, g = (0, -gravity)
  return model::wrapAngle(std::atan2(f_world.y(), f_world.x()) - std::atan2(f_body.y(), f_body.x()));
}

void PitchFilter::reset(double pitch, double gyro_bias) {
  pitch_ = pitch;
  bias_ = gyro_bias;
  rate_ = 0.0;
  used_ = false;
}

void PitchFilter::update(double gyro, const Eigen::Vector2d& f_body, const Eigen::Vector2d& accel_world, double dt) {
  const Eigen::Vector2d a = params_.compensate_acceleration ? accel_world : Eigen::Vector2d::Zero();
  const double expected = Eigen::Vector2d(a.x(), a.y() + gravity_).norm();
  used_ = std::abs(f_body.norm() - expected) < params_.accel_gate_mps2;
  double e = 0.0;
  if (used_) e = model::wrapAngle(tiltFromSpecificForce(f_body, a, gravity_) - pitch_);
  rate_ = gyro - bias_;
  pitch_ = model::wrapAngle(pitch_ + dt * (rate_ + e / params_.correction_time_constant_s));
  bias_ -= dt * params_.gyro_bias_gain * e;
}

}  // namespace mft::estimator
