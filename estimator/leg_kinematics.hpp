#pragma once
// Foot position and velocity relative to the base, in the base frame, from all four encoders of a leg.
// Both chains end at the foot (rear shank tip = model's contact point, fore shank tip = closure point); their
// average halves the encoder noise and equals either chain when the loop is closed.
#include <Eigen/Core>
#include <array>

#include "model/five_bar.hpp"
#include "model/robot_io.hpp"

namespace mft::estimator {

struct LegJoints {
  std::array<double, 4> pos{};  // [hip_rear, knee_rear, hip_fore, knee_fore] (generalized-coordinate order)
  std::array<double, 4> vel{};
};

// The leg's encoder readings in generalized-coordinate order (robot_io's arrays are [rear, fore] per leg).
LegJoints legJoints(const model::SensorReadings& s, int leg);

struct FootInBase {
  Eigen::Vector2d pos{0, 0};  // base frame [x, z]
  Eigen::Vector2d vel{0, 0};  // rate of pos as seen in the base frame
};

FootInBase footInBase(const model::FiveBarGeometry& g, const LegJoints& j);

}  // namespace mft::estimator
