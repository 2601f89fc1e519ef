// PlannerStateBuilder: the planner's view of a RobotStateEstimate through the full-body model.
#include <gtest/gtest.h>

#include <cmath>

#include "model/planar_dynamics.hpp"
#include "planner/motion_planner.hpp"
#include "planner/planner_state.hpp"

using namespace mft;

TEST(PlannerStateBuilder, FeetAndComComeFromTheModel) {
  const auto d = model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  const Eigen::Vector3d base(0.3, 0.41, 0.05);
  const Eigen::Vector2d right(0.06, -0.40), left(-0.05, -0.39);
  model::RobotStateEstimate est;
  est.tick = 7;
  est.time_s = 0.007;
  est.q = model::closedLoopConfiguration(d, base, right, left);
  est.qd.setZero();
  est.qd[0] = 0.2;  // pure base translation: every point moves at 0.2 m/s
  est.contact = {true, false};

  planner::PlannerStateBuilder builder(d);
  const planner::PlannerState s = builder.build(est);
  const Eigen::Matrix2d R = (Eigen::Matrix2d() << std::cos(0.05), -std::sin(0.05), std::sin(0.05), std::cos(0.05)).finished();
  EXPECT_NEAR((s.foot_pos[0] - (base.head<2>() + R * right)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((s.foot_pos[1] - (base.head<2>() + R * left)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((s.foot_vel[0] - Eigen::Vector2d(0.2, 0.0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((s.com_vel - Eigen::Vector2d(0.2, 0.0)).norm(), 0.0, 1e-9);
  EXPECT_GT(s.com.y(), base.y() - 0.2);  // the torso (70 % of the mass) is above the hips
  EXPECT_LT(s.com.y(), base.y() + 0.1);
  EXPECT_DOUBLE_EQ(s.base_z, 0.41);
  EXPECT_EQ(s.tick, 7u);
  EXPECT_EQ(s.contact, est.contact);

  // And the planner accepts it: standing holds both feet where the model puts them.
  planner::MotionPlanner planner(planner::loadPlannerConfig(std::string(MFT_CONFIG_DIR) + "/planner.yaml"), d);
  const auto& plan = planner.update(s);
  EXPECT_NEAR((plan.foot[0].pos - s.foot_pos[0]).norm(), 0.0, 1e-12);
}
