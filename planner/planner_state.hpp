#pragma once
// What the planner reads from the robot state: base height, CoM and feet in the world frame, contact flags.
// PlannerStateBuilder derives it from a RobotStateEstimate through the full-body model (model/planar_dynamics).
#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "model/planar_dynamics.hpp"
#include "model/robot_io.hpp"

namespace mft::planner {

struct PlannerState {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  double base_z = 0.0;
  Eigen::Vector2d com{0, 0}, com_vel{0, 0};  // world [x, z]
  std::array<Eigen::Vector2d, model::kNumLegs> foot_pos{}, foot_vel{};  // world [x, z], right then left
  std::array<bool, model::kNumLegs> contact{};
};

class PlannerStateBuilder {
 public:
  explicit PlannerStateBuilder(const model::RobotDescription& robot);
  PlannerState build(const model::RobotStateEstimate& est);

 private:
  model::PlanarModel model_;
  model::ModelData data_;
};

}  // namespace mft::planner
