#include "estimator/contact_detector.hpp"

#include <Eigen/LU>
#include <cmath>

namespace mft::estimator {

bool estimateFootForce(const model::FiveBarGeometry& g, double q_rear, double q_fore, const Eigen::Vector2d& tau,
                       Eigen::Vector2d* force_base) {
  model::FiveBarPose pose;
  if (model::fiveBarForward(g, q_rear, q_fore, &pose) != model::FiveBarStatus::Ok) return false;
  const Eigen::Matrix2d J = model::fiveBarFootJacobian(g, pose);
  if (!J.allFinite() || std::abs(J.determinant()) < 1e-9) return false;
  *force_base = -J.transpose().inverse() * tau;
  return force_base->allFinite();
}

std::array<bool, model::kNumLegs> ContactDetector::update(const model::SensorReadings& s, double pitch) {
  const double c = std::cos(pitch), sn = std::sin(pitch);
  const Eigen::Matrix2d R = (Eigen::Matrix2d() << c, -sn, sn, c).finished();
  std::array<bool, model::kNumLegs> out{};
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    const int rear = 2 * leg, fore = 2 * leg + 1;
    Eigen::Vector2d f_base;
    const bool ok = estimateFootForce(geometry_, s.actuated_pos[rear], s.actuated_pos[fore],
                                      {s.sea_torque[rear], s.sea_torque[fore]}, &f_base);
    force_[leg] = ok ? Eigen::Vector2d(R * f_base) : Eigen::Vector2d::Zero();
    const double fz = force_[leg].y();
    if (fz > params_.force_on_N) force_contact_[leg] = true;
    else if (fz < params_.force_off_N) force_contact_[leg] = false;

    const bool sw = s.contact[leg], fc = force_contact_[leg];
    switch (params_.source) {
      case ContactSource::Switch: out[leg] = sw; break;
      case ContactSource::Force: out[leg] = fc; break;
      case ContactSource::Either: out[leg] = sw || fc; break;
      case ContactSource::Both: out[leg] = sw && fc; break;
    }
  }
  return out;
}

}  // namespace mft::estimator
