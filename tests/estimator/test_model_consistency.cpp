// The estimator's leg kinematics agree with the full-body model's contact point (rear shank tip) and its
// Jacobian, so the estimator and the controller share one foot.
#include <gtest/gtest.h>

#include "estimator/leg_kinematics.hpp"
#include "model/planar_dynamics.hpp"

using namespace mft;

TEST(ModelConsistency, FootInBaseMatchesTheModelContactPoint) {
  const auto d = model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  const auto m = model::buildBipedModel(d);
  const auto g = model::FiveBarGeometry::from(d);
  const Eigen::Vector3d base(0.0, 0.0, 0.0);  // base frame = world frame
  const model::VectorQ q = model::closedLoopConfiguration(d, base, {0.07, -0.38}, {-0.04, -0.41});
  model::VectorQ qd = model::VectorQ::Zero();
  // A leg motion consistent with the closure: pick hip rates, derive knee rates from the five-bar.
  for (int leg = 0; leg < 2; ++leg) {
    model::FiveBarPose pose;
    model::fiveBarForward(g, q[model::hipRearIndex(leg)], q[model::hipForeIndex(leg)], &pose);
    const Eigen::Vector2d hip_rates(0.7 - leg, -0.4 + 0.9 * leg);
    const Eigen::Vector2d knee_rates = model::fiveBarKneeRates(g, pose, hip_rates);
    qd[model::hipRearIndex(leg)] = hip_rates[0];
    qd[model::hipForeIndex(leg)] = hip_rates[1];
    qd[model::kneeRearIndex(leg)] = knee_rates[0];
    qd[model::kneeForeIndex(leg)] = knee_rates[1];
  }
  model::ModelData data;
  model::updateModel(m, q, qd, &data);
  for (int leg = 0; leg < 2; ++leg) {
    estimator::LegJoints j;
    j.pos = {q[model::hipRearIndex(leg)], q[model::kneeRearIndex(leg)], q[model::hipForeIndex(leg)], q[model::kneeForeIndex(leg)]};
    j.vel = {qd[model::hipRearIndex(leg)], qd[model::kneeRearIndex(leg)], qd[model::hipForeIndex(leg)], qd[model::kneeForeIndex(leg)]};
    const auto f = estimator::footInBase(g, j);
    EXPECT_NEAR((f.pos - data.foot_pos.segment<2>(2 * leg)).norm(), 0.0, 1e-9) << leg;
    EXPECT_NEAR((f.vel - data.foot_vel.segment<2>(2 * leg)).norm(), 0.0, 1e-9) << leg;
  }
}
