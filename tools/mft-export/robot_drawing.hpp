#pragma once
// What a video frame draws of the robot, in world coordinates (x forward, z up), computed with the project's
// own kinematics: the five-bar forward kinematics closes each leg from its two recorded hip angles, and the
// planar model's body poses place the torso, thighs and shanks in the world. No DDS or MRPT here.
#include <Eigen/Core>
#include <array>

#include "model/coordinates.hpp"
#include "model/five_bar.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"

namespace mft::video {

struct LegDrawing {
  Eigen::Vector2d hip_rear{0, 0}, hip_fore{0, 0};    // the two hip joints (coincide when the hips are coaxial)
  Eigen::Vector2d knee_rear{0, 0}, knee_fore{0, 0};  // the passive knees
  Eigen::Vector2d foot{0, 0};                        // distal end of the rear shank: the contact point
  Eigen::Vector2d foot_fore{0, 0};                   // distal end of the fore shank (= foot when the loop is closed)
  // false: the five-bar could not be closed from the hip angles (unreachable or degenerate); the recorded
  // passive knee angles were drawn instead.
  bool closed_by_kinematics = true;
};

struct RobotDrawing {
  Eigen::Vector3d base{0, 0, 0};                // x, z, pitch of the base frame (origin on the hip axis)
  std::array<Eigen::Vector2d, 4> torso{};       // corners of the torso's collision box, counter-clockwise
  Eigen::Vector2d torso_com{0, 0};              // where the boom holds the torso
  std::array<LegDrawing, model::kNumLegs> legs{};
};

class RobotDrawer {
 public:
  explicit RobotDrawer(const model::RobotDescription& description);
  // The robot at generalized coordinates q = [x, z, pitch, q4 .. q11]; only the hip angles of the legs are
  // used when the five-bar closes (the passive knees follow from them).
  RobotDrawing draw(const model::VectorQ& q) const;

 private:
  model::RobotDescription description_;
  model::PlanarModel model_;
  model::FiveBarGeometry geometry_;
};

}  // namespace mft::video
