#pragma once
// Linear Kalman filter for the IMU point and the feet (planar version of the MIT Cheetah 3 estimator,
// Bledt et al. 2018). State (world): [p_imu x, z, v_imu x, z, right foot x, z, left foot x, z].
//   predict:  p += v dt + a dt^2/2, v += a dt with a = R(pitch) f_imu + g; feet constant (random walk).
//   correct (stance feet only): foot - p = r (encoders), -v = r_dot (the foot does not move), and optionally
//            foot_z = ground height. r = R(pitch)(foot_in_base - imu_in_base) and its world rate.
// A swing foot's state is replaced by p + r each tick (its covariance correlated with p), so it lands with
// a consistent estimate. The IMU point is estimated instead of the base origin so that the prediction needs no
// angular acceleration; the pitch comes from PitchFilter and is treated as known here.
#include <Eigen/Core>
#include <array>

#include "estimator/estimator_config.hpp"
#include "model/coordinates.hpp"

namespace mft::estimator {

class BaseKalmanFilter {
 public:
  static constexpr int kN = 8;
  using State = Eigen::Matrix<double, kN, 1>;
  using Cov = Eigen::Matrix<double, kN, kN>;
  using Vec2 = Eigen::Vector2d;
  using LegArray = std::array<Vec2, model::kNumLegs>;

  explicit BaseKalmanFilter(const KalmanParams& params) : params_(params) {}

  void reset(const Vec2& p_imu, const Vec2& v_imu, const LegArray& feet);
  void predict(const Vec2& accel_world, double dt);
  // foot_rel: world vector from the IMU point to each foot; foot_rel_rate: its rate from the joint motion and
  // the pitch rate (world frame).
  void correct(const LegArray& foot_rel, const LegArray& foot_rel_rate, const std::array<bool, model::kNumLegs>& stance);

  Vec2 position() const { return x_.segment<2>(0); }
  Vec2 velocity() const { return x_.segment<2>(2); }
  Vec2 foot(int leg) const { return x_.segment<2>(4 + 2 * leg); }
  const State& state() const { return x_; }
  const Cov& covariance() const { return P_; }

 private:
  KalmanParams params_;
  State x_ = State::Zero();
  Cov P_ = Cov::Identity();
};

}  // namespace mft::estimator
