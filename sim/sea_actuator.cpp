#include "sim/sea_actuator.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mft::sim {
namespace {

// exp(A) by scaling and squaring with a Taylor series: plenty for a small A with |A| ~ 1 (exact discretisation).
template <int N>
Eigen::Matrix<double, N, N> expm(const Eigen::Matrix<double, N, N>& a) {
  using M = Eigen::Matrix<double, N, N>;
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  while (norm / std::ldexp(1.0, squarings) > 0.25) ++squarings;
  const M s = a / std::ldexp(1.0, squarings);
  M term = M::Identity(), sum = M::Identity();
  for (int k = 1; k <= 14; ++k) {
    term = term * s / k;
    sum += term;
  }
  for (int i = 0; i < squarings; ++i) sum = sum * sum;
  return sum;
}

}  // namespace

SeaActuator::SeaActuator(double w, double zeta, double h, const SeaLimits& limits) : limits_(limits) {
  // Augmented system [tau, tau', u] with u constant over the step: exp gives A_d and B_d at once.
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 1) = 1.0;
  m(1, 0) = -w * w;
  m(1, 1) = -2.0 * zeta * w;
  m(1, 2) = w * w;
  const Eigen::Matrix3d e = expm<3>(m * h);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) ad_[i][j] = e(i, j);
    bd_[i] = e(i, 2);
  }
}

void SeaActuator::reset(double torque) {
  tau_ = torque;
  tau_dot_ = 0.0;
}

double SeaActuator::limitedInput(double command, double omega) const {
  double u = std::clamp(command, -limits_.peak_torque, limits_.peak_torque);
  if (u * omega > 0.0) {  // driving in the direction of motion: back-EMF limits the speed
    const double fade = std::clamp((limits_.speed_limit - std::abs(omega)) / limits_.speed_band, 0.0, 1.0);
    u *= fade;
  }
  return u;
}

void SeaActuator::advance(double input) {
  const double t = ad_[0][0] * tau_ + ad_[0][1] * tau_dot_ + bd_[0] * input;
  const double td = ad_[1][0] * tau_ + ad_[1][1] * tau_dot_ + bd_[1] * input;
  tau_ = std::clamp(t, -limits_.peak_torque, limits_.peak_torque);
  tau_dot_ = td;
}

double seaSettlingTime(double w, double zeta, double h) {
  SeaActuator sea(w, zeta, h, {1e9, 1e9, 1.0});
  double last_outside = 0.0;
  for (int k = 1; k * h < 1.0; ++k) {
    sea.advance(1.0);
    if (std::abs(sea.torque() - 1.0) > 0.02) last_outside = k * h;
  }
  return last_outside;
}

SeaMotorActuator::SeaMotorActuator(const SeaMotorParams& params, double h, const SeaLimits& limits)
    : params_(params), limits_(limits) {
  const double jr = params.reflected_inertia_kgm2, ks = params.spring_stiffness_Nmprad;
  const double br = params.reflected_damping_Nmsprad, w = params.natural_frequency_radps;
  if (!(jr > 0.0 && ks > 0.0 && br >= 0.0 && w > 0.0 && params.damping_ratio > 0.0))
    throw std::invalid_argument("SeaMotorActuator: inertia, stiffness, frequency and damping ratio must be > 0, damping >= 0");
  kp_ = w * w * jr / ks - 1.0;
  kd_ = (2.0 * params.damping_ratio * w * jr - br) / ks;
  if (!(kp_ > -1.0) || kd_ < 0.0)
    throw std::invalid_argument("SeaMotorActuator: the loop cannot reach w = " + std::to_string(w) +
                                " rad/s, zeta = " + std::to_string(params.damping_ratio) +
                                " with this motor and spring (Kp = " + std::to_string(kp_) +
                                ", Kd = " + std::to_string(kd_) + " s)");
  if (!(params.loop_period_s > 0.0)) throw std::invalid_argument("SeaMotorActuator: the loop period must be > 0");
  // Whole loop periods per physics step, at least as fast as asked (tests change the substeps after loading).
  loop_steps_ = std::max(1, static_cast<int>(std::ceil(h / params.loop_period_s * (1.0 - 1e-9))));
  // Augmented [deflection, motor speed, tau_m, joint rate] with the inputs constant over a loop period.
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 1) = 1.0;   // deflection' = motor speed - joint rate
  m(0, 3) = -1.0;
  m(1, 0) = -ks / jr;  // J_r motor speed' = tau_m - k_s deflection - b_r motor speed
  m(1, 1) = -br / jr;
  m(1, 2) = 1.0 / jr;
  const Eigen::Matrix4d e = expm<4>(m * (h / loop_steps_));
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      ad_[i][j] = e(i, j);
      bd_[i][j] = e(i, 2 + j);
    }
}

void SeaMotorActuator::reset(double torque, double joint_rate) {
  deflection_ = torque / params_.spring_stiffness_Nmprad;
  motor_speed_ = joint_rate;
  mean_motor_torque_ = torque;
}

double SeaMotorActuator::motorTorque(double command, double joint_rate) const {
  const double ks = params_.spring_stiffness_Nmprad;
  const double tau_s = ks * deflection_, tau_s_rate = ks * (motor_speed_ - joint_rate);
  double u = command + kp_ * (command - tau_s) - kd_ * tau_s_rate;
  u = std::clamp(u, -limits_.peak_torque, limits_.peak_torque);
  if (u * motor_speed_ > 0.0) {  // driving in the direction of motion: back-EMF limits the motor speed
    const double fade = std::clamp((limits_.speed_limit - std::abs(motor_speed_)) / limits_.speed_band, 0.0, 1.0);
    u *= fade;
  }
  return u;
}

void SeaMotorActuator::advance(double command, double joint_rate) {
  // The drive accepts no command beyond its rating.
  const double tau_d = std::clamp(command, -limits_.peak_torque, limits_.peak_torque);
  double sum = 0.0;
  for (int k = 0; k < loop_steps_; ++k) {
    const double u = motorTorque(tau_d, joint_rate);
    sum += u;
    const double d = ad_[0][0] * deflection_ + ad_[0][1] * motor_speed_ + bd_[0][0] * u + bd_[0][1] * joint_rate;
    const double v = ad_[1][0] * deflection_ + ad_[1][1] * motor_speed_ + bd_[1][0] * u + bd_[1][1] * joint_rate;
    deflection_ = d;
    motor_speed_ = v;
  }
  mean_motor_torque_ = sum / loop_steps_;
}

}  // namespace mft::sim
