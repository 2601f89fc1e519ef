#pragma once
// Foot contact from the switches and/or the normal force estimated from the SEA torques. The force estimate
// is quasi-static (leg inertia and weight neglected, the legs are ~14 % of the mass): tau = -J' f, J the
// five-bar foot Jacobian d foot / d(hip_rear, hip_fore), f the ground force on the foot; rotated to the world.
#include <array>

#include "estimator/estimator_config.hpp"
#include "model/five_bar.hpp"
#include "model/robot_io.hpp"

namespace mft::estimator {

class ContactDetector {
 public:
  ContactDetector(const ContactParams& params, const model::FiveBarGeometry& geometry)
      : params_(params), geometry_(geometry) {}

  // `pitch` rotates the base-frame force estimate to the world.
  std::array<bool, model::kNumLegs> update(const model::SensorReadings& s, double pitch);
  void reset() { force_contact_ = {false, false}; }
  // Last estimated world ground force on each foot [x, z] (zero where the leg is singular).
  const std::array<Eigen::Vector2d, model::kNumLegs>& force() const { return force_; }

 private:
  ContactParams params_;
  model::FiveBarGeometry geometry_;
  std::array<bool, model::kNumLegs> force_contact_{};
  std::array<Eigen::Vector2d, model::kNumLegs> force_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
};

// The quasi-static ground force on a foot, base frame, from the two hip torques [rear, fore]; false if the
// pose is singular or the loop cannot close.
bool estimateFootForce(const model::FiveBarGeometry& g, double q_rear, double q_fore, const Eigen::Vector2d& tau,
                       Eigen::Vector2d* force_base);

}  // namespace mft::estimator
