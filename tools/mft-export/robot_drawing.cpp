#include "tools/mft-export/robot_drawing.hpp"

namespace mft::video {

using Eigen::Vector2d;

RobotDrawer::RobotDrawer(const model::RobotDescription& description)
    : description_(description),
      model_(model::buildBipedModel(description)),
      geometry_(model::FiveBarGeometry::from(description)) {}

RobotDrawing RobotDrawer::draw(const model::VectorQ& q) const {
  RobotDrawing out;
  out.base = q.head<3>();
  // The passive knees from the five-bar's closure (the recorded ones only when it cannot close), so the
  // drawing shows what the kinematics says the recorded hip angles mean.
  model::VectorQ closed = q;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    model::FiveBarPose pose;
    const auto status = model::fiveBarForward(geometry_, q[model::hipRearIndex(leg)], q[model::hipForeIndex(leg)], &pose);
    auto& drawn = out.legs[static_cast<std::size_t>(leg)];
    drawn.closed_by_kinematics = status == model::FiveBarStatus::Ok;
    if (drawn.closed_by_kinematics) {
      closed[model::kneeRearIndex(leg)] = pose.knee_rear;
      closed[model::kneeForeIndex(leg)] = pose.knee_fore;
    }
  }
  constexpr int kTorsoBody = model::kBasePitch;  // body 2 carries the torso; its frame is the base frame
  const Vector2d com(description_.torso_com_m[0], description_.torso_com_m[1]);
  const Vector2d half(0.5 * description_.torso_size_m[0], 0.5 * description_.torso_size_m[1]);
  const std::array<Vector2d, 4> corners = {Vector2d(-half.x(), -half.y()), Vector2d(half.x(), -half.y()),
                                           Vector2d(half.x(), half.y()), Vector2d(-half.x(), half.y())};
  for (std::size_t i = 0; i < corners.size(); ++i)
    out.torso[i] = model::pointPosition(model_, closed, kTorsoBody, com + corners[i]);
  out.torso_com = model::pointPosition(model_, closed, kTorsoBody, com);
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    auto& drawn = out.legs[static_cast<std::size_t>(leg)];
    // A body frame's origin is its proximal joint: thighs at the hips, shanks at the knees.
    drawn.hip_rear = model::bodyPose(model_, closed, model::hipRearIndex(leg)).head<2>();
    drawn.hip_fore = model::bodyPose(model_, closed, model::hipForeIndex(leg)).head<2>();
    drawn.knee_rear = model::bodyPose(model_, closed, model::kneeRearIndex(leg)).head<2>();
    drawn.knee_fore = model::bodyPose(model_, closed, model::kneeForeIndex(leg)).head<2>();
    drawn.foot = model::pointPosition(model_, closed, model_.rearShankBody(leg), model_.shankTip());
    drawn.foot_fore = model::pointPosition(model_, closed, model_.foreShankBody(leg), model_.shankTip());
  }
  return out;
}

}  // namespace mft::video
