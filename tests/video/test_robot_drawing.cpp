// The points a run video draws (tools/mft-export/robot_drawing.hpp) against independent geometry: feet where
// closedLoopConfiguration put them (its inverse kinematics), knees at one thigh length from the hips along the
// absolute thigh angle, passive knees recomputed from the hip angles by the five-bar closure.
#include <gtest/gtest.h>

#include <cmath>

#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"
#include "tools/mft-export/robot_drawing.hpp"

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using mft::model::VectorQ;

mft::model::RobotDescription robot() { return mft::model::loadRobotDescription(MFT_CONFIG_DIR "/robot.yaml"); }

// World point of a base-frame offset: rotate CCW by pitch, then translate (written out here on purpose).
Vector2d world(const Vector3d& base, const Vector2d& offset) {
  const double c = std::cos(base.z()), s = std::sin(base.z());
  return {base.x() + c * offset.x() - s * offset.y(), base.y() + s * offset.x() + c * offset.y()};
}

struct Pose {
  Vector3d base;
  Vector2d right, left;  // feet in the base frame
};

const Pose kPoses[] = {
    {{0.0, 0.42, 0.0}, {0.0, -0.42}, {0.0, -0.42}},
    {{1.3, 0.40, 0.12}, {0.08, -0.39}, {-0.06, -0.41}},
    {{-0.7, 0.45, -0.2}, {-0.12, -0.36}, {0.15, -0.30}},
    {{3.0, 0.35, 0.05}, {0.02, -0.25}, {0.0, -0.44}},
};

void expectNear(const Vector2d& a, const Vector2d& b, double tol, const char* what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": (" << a.transpose() << ") vs (" << b.transpose() << ")";
}

TEST(RobotDrawing, FeetHipsKneesAndTorsoWhereTheGeometryPutsThem) {
  const auto d = robot();
  const mft::video::RobotDrawer drawer(d);
  for (const auto& pose : kPoses) {
    const VectorQ q = mft::model::closedLoopConfiguration(d, pose.base, pose.right, pose.left);
    const auto drawing = drawer.draw(q);
    EXPECT_LT((drawing.base - pose.base).norm(), 1e-15);
    for (int leg = 0; leg < 2; ++leg) {
      const auto& l = drawing.legs[static_cast<std::size_t>(leg)];
      EXPECT_TRUE(l.closed_by_kinematics);
      expectNear(l.foot, world(pose.base, leg == 0 ? pose.right : pose.left), 1e-9, "foot");
      expectNear(l.foot_fore, l.foot, 1e-9, "fore shank tip");
      // Coaxial hips (hip_spacing 0): both hips on the base origin.
      expectNear(l.hip_rear, world(pose.base, {-0.5 * d.hip_spacing_m, 0.0}), 1e-12, "rear hip");
      expectNear(l.hip_fore, world(pose.base, {0.5 * d.hip_spacing_m, 0.0}), 1e-12, "fore hip");
      // Knee = hip + l1 (sin a, -cos a) with a = pitch + hip angle (absolute thigh angle).
      const double a_rear = pose.base.z() + q[mft::model::hipRearIndex(leg)];
      const double a_fore = pose.base.z() + q[mft::model::hipForeIndex(leg)];
      expectNear(l.knee_rear, l.hip_rear + d.thigh.length_m * Vector2d(std::sin(a_rear), -std::cos(a_rear)), 1e-12,
                 "rear knee");
      expectNear(l.knee_fore, l.hip_fore + d.thigh.length_m * Vector2d(std::sin(a_fore), -std::cos(a_fore)), 1e-12,
                 "fore knee");
      EXPECT_NEAR((l.foot - l.knee_rear).norm(), d.shank.length_m, 1e-9);
      EXPECT_NEAR((l.foot_fore - l.knee_fore).norm(), d.shank.length_m, 1e-9);
    }
    // Torso box: centred on the CoM (rotated with the base), sides of the described size.
    const Vector2d com = world(pose.base, {d.torso_com_m[0], d.torso_com_m[1]});
    expectNear(drawing.torso_com, com, 1e-12, "torso CoM");
    const Vector2d centre = 0.25 * (drawing.torso[0] + drawing.torso[1] + drawing.torso[2] + drawing.torso[3]);
    expectNear(centre, com, 1e-12, "torso centre");
    EXPECT_NEAR((drawing.torso[1] - drawing.torso[0]).norm(), d.torso_size_m[0], 1e-12);
    EXPECT_NEAR((drawing.torso[2] - drawing.torso[1]).norm(), d.torso_size_m[1], 1e-12);
    // The box's long side turns with the pitch.
    const Vector2d side = drawing.torso[1] - drawing.torso[0];
    EXPECT_NEAR(std::atan2(side.y(), side.x()), pose.base.z(), 1e-12);
  }
}

TEST(RobotDrawing, PassiveKneesComeFromTheFiveBarNotFromTheRecord) {
  const auto d = robot();
  const mft::video::RobotDrawer drawer(d);
  const Pose& pose = kPoses[1];
  const VectorQ q = mft::model::closedLoopConfiguration(d, pose.base, pose.right, pose.left);
  VectorQ wrong_knees = q;
  for (int leg = 0; leg < 2; ++leg) {
    wrong_knees[mft::model::kneeRearIndex(leg)] += 0.4;
    wrong_knees[mft::model::kneeForeIndex(leg)] -= 0.3;
  }
  const auto a = drawer.draw(q), b = drawer.draw(wrong_knees);
  for (std::size_t leg = 0; leg < 2; ++leg) {
    expectNear(b.legs[leg].foot, a.legs[leg].foot, 1e-9, "foot");
    expectNear(b.legs[leg].knee_rear, a.legs[leg].knee_rear, 1e-12, "rear knee");
    expectNear(b.legs[leg].foot_fore, b.legs[leg].foot, 1e-9, "closure");
  }
}

TEST(RobotDrawing, SeparateHipAxesAreDrawnApart) {
  auto d = robot();
  d.hip_spacing_m = 0.08;
  const mft::video::RobotDrawer drawer(d);
  const Pose& pose = kPoses[2];
  const VectorQ q = mft::model::closedLoopConfiguration(d, pose.base, pose.right, pose.left);
  const auto drawing = drawer.draw(q);
  for (std::size_t leg = 0; leg < 2; ++leg) {
    expectNear(drawing.legs[leg].hip_rear, world(pose.base, {-0.04, 0.0}), 1e-12, "rear hip");
    expectNear(drawing.legs[leg].hip_fore, world(pose.base, {0.04, 0.0}), 1e-12, "fore hip");
    expectNear(drawing.legs[leg].foot, world(pose.base, leg == 0 ? pose.right : pose.left), 1e-9, "foot");
  }
}

TEST(RobotDrawing, ALegTheFiveBarCannotCloseKeepsItsRecordedKnees) {
  const auto d = robot();
  const mft::video::RobotDrawer drawer(d);
  VectorQ q = VectorQ::Zero();
  q[mft::model::kBaseZ] = 0.45;
  // Equal hip angles on coaxial hips: the knees coincide and the foot is undetermined (Degenerate).
  q[mft::model::hipRearIndex(0)] = q[mft::model::hipForeIndex(0)] = 0.3;
  q[mft::model::kneeRearIndex(0)] = 0.5;
  q[mft::model::kneeForeIndex(0)] = -0.5;
  q[mft::model::hipRearIndex(1)] = -0.6;
  q[mft::model::hipForeIndex(1)] = 0.6;
  const auto drawing = drawer.draw(q);
  EXPECT_FALSE(drawing.legs[0].closed_by_kinematics);
  EXPECT_TRUE(drawing.legs[1].closed_by_kinematics);
  // Drawn with the recorded knee angles: the rear shank at absolute angle 0.3 + 0.5.
  const auto& l = drawing.legs[0];
  expectNear(l.foot, l.knee_rear + d.shank.length_m * Vector2d(std::sin(0.8), -std::cos(0.8)), 1e-12, "rear shank");
  expectNear(l.foot_fore, l.knee_fore + d.shank.length_m * Vector2d(std::sin(-0.2), -std::cos(-0.2)), 1e-12, "fore shank");
}

}  // namespace
