#include "sim/sea_actuator.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace mft::sim {
namespace {

// exp(A) by scaling and squaring with a Taylor series: plenty for a 3x3 with |A| ~ 1 (exact discretisation).
Eigen::Matrix3d expm(const Eigen::Matrix3d& a) {
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  while (norm / std::ldexp(1.0, squarings) > 0.25) ++squarings;
  const Eigen::Matrix3d s = a / std::ldexp(1.0, squarings);
  Eigen::Matrix3d term = Eigen::Matrix3d::Identity(), sum = Eigen::Matrix3d::Identity();
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
  const Eigen::Matrix3d e = expm(m * h);
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

}  // namespace mft::sim
