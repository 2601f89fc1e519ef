#include "estimator/base_kalman_filter.hpp"

#include <Eigen/Cholesky>

namespace mft::estimator {

void BaseKalmanFilter::reset(const Vec2& p_imu, const Vec2& v_imu, const LegArray& feet) {
  x_ << p_imu, v_imu, feet[0], feet[1];
  P_.setZero();
  const double sp = params_.initial_position_std_m, sv = params_.initial_velocity_std_mps;
  P_.diagonal() << sp * sp, sp * sp, sv * sv, sv * sv, sp * sp, sp * sp, sp * sp, sp * sp;
}

void BaseKalmanFilter::predict(const Vec2& a, double dt) {
  x_.segment<2>(0) += dt * x_.segment<2>(2) + 0.5 * dt * dt * a;
  x_.segment<2>(2) += dt * a;

  Cov F = Cov::Identity();
  F.block<2, 2>(0, 2) = dt * Eigen::Matrix2d::Identity();
  // White acceleration noise of density q integrated over dt (continuous-time model, discretized exactly).
  const double qa = params_.accel_noise_density * params_.accel_noise_density;
  const double qf = params_.foot_slip_density * params_.foot_slip_density;
  Cov Q = Cov::Zero();
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  Q.block<2, 2>(0, 0) = qa * dt * dt * dt / 3.0 * I;
  Q.block<2, 2>(0, 2) = Q.block<2, 2>(2, 0) = qa * dt * dt / 2.0 * I;
  Q.block<2, 2>(2, 2) = qa * dt * I;
  Q.block<4, 4>(4, 4) = qf * dt * Eigen::Matrix4d::Identity();
  P_ = F * P_ * F.transpose() + Q;
}

void BaseKalmanFilter::correct(const LegArray& rel, const LegArray& rel_rate,
                               const std::array<bool, model::kNumLegs>& stance) {
  const double sp2 = params_.kinematic_position_std_m * params_.kinematic_position_std_m;
  const double sv2 = params_.kinematic_velocity_std_mps * params_.kinematic_velocity_std_mps;
  const double sg2 = params_.ground_height_std_m * params_.ground_height_std_m;

  // Swing feet: foot := p + rel, with cov(foot, .) = cov(p, .) plus the measurement noise on the foot block.
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    if (stance[leg]) continue;
    const int f = 4 + 2 * leg;
    x_.segment<2>(f) = x_.segment<2>(0) + rel[leg];
    Cov T = Cov::Identity();
    T.block<2, 2>(f, f).setZero();
    T.block<2, 2>(f, 0) = Eigen::Matrix2d::Identity();
    P_ = T * P_ * T.transpose();
    P_.block<2, 2>(f, f) += sp2 * Eigen::Matrix2d::Identity();
  }

  // Stance rows per leg: [foot - p (2), -v (2), foot z (1)]. Inactive rows stay zero and carry no information.
  constexpr int kM = 5 * model::kNumLegs;
  Eigen::Matrix<double, kM, kN> H = Eigen::Matrix<double, kM, kN>::Zero();
  Eigen::Matrix<double, kM, 1> y = Eigen::Matrix<double, kM, 1>::Zero();
  Eigen::Matrix<double, kM, 1> r = Eigen::Matrix<double, kM, 1>::Ones();
  bool any = false;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    if (!stance[leg]) continue;
    any = true;
    const int row = 5 * leg, f = 4 + 2 * leg;
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    H.block<2, 2>(row, f) = I;
    H.block<2, 2>(row, 0) = -I;
    y.segment<2>(row) = rel[leg] - (x_.segment<2>(f) - x_.segment<2>(0));
    r.segment<2>(row).setConstant(sp2);
    H.block<2, 2>(row + 2, 2) = -I;
    y.segment<2>(row + 2) = rel_rate[leg] - (-x_.segment<2>(2));
    r.segment<2>(row + 2).setConstant(sv2);
    if (params_.use_ground_height) {
      H(row + 4, f + 1) = 1.0;
      y(row + 4) = params_.ground_height_m - x_(f + 1);
      r(row + 4) = sg2;
    }
  }
  if (!any) return;

  const Eigen::Matrix<double, kM, kM> S = H * P_ * H.transpose() + Eigen::Matrix<double, kM, kM>(r.asDiagonal());
  const Eigen::Matrix<double, kN, kM> K = S.ldlt().solve(H * P_).transpose();
  x_ += K * y;
  // Joseph form: stays symmetric positive definite with very different noise scales.
  const Cov IKH = Cov::Identity() - K * H;
  P_ = IKH * P_ * IKH.transpose() + K * r.asDiagonal() * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
}

}  // namespace mft::estimator
