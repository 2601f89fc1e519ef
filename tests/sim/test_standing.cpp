// Standing under the simple PD + gravity feed-forward controller: loop closure, contact forces, IMU, reset.
#include <gtest/gtest.h>

#include <cmath>

#include "model/planar_dynamics.hpp"
#include "sim_test_support.hpp"

using namespace mft::sim;
using mft::model::VectorQ;

namespace {
StandingPose stance() {
  StandingPose p;
  p.base_height_m = 0.40;
  p.foot_offset_x_m = {0.06, -0.06};  // a support base: with both feet under the hip axis the robot is a point
  return p;                           // on a pivot and no joint-space PD can hold its pitch
}
}  // namespace

class SimStanding : public ::testing::TestWithParam<int> {};

TEST_P(SimStanding, HoldsWithClosedLoopsAndWeightOnFeet) {
  auto o = test::options();
  o.substeps = GetParam();
  Simulator sim(test::robot(), o, Terrain::flat());
  sim.reset(stance());
  test::StanceController ctrl(sim.robot(), sim.groundTruth().q, 300.0, 6.0);
  const double weight = sim.robot().totalMass() * sim.robot().gravity_mps2;
  double fz_sum = 0.0, az_sum = 0.0;
  int n = 0;
  for (int k = 0; k < 5000; ++k) {
    sim.setCommand(ctrl.command(sim.sensors()));
    sim.step();
    if (k >= 4000) {
      const auto& f = sim.groundTruth().contact_force;
      fz_sum += f[1] + f[3];
      az_sum += sim.sensors().accel[1];
      ++n;
      EXPECT_TRUE(sim.sensors().contact[0] && sim.sensors().contact[1]);
    }
  }
  const auto& gt = sim.groundTruth();
  std::cout << "substeps " << o.substeps << ": z " << gt.q[1] << " pitch " << gt.q[2] << " max closure error "
            << sim.stats().max_closure_error_m << " m, sum Fz / mg - 1 = " << fz_sum / n / weight - 1.0
            << ", IMU a_z " << az_sum / n << "\n";
  EXPECT_LT(sim.stats().max_closure_error_m, 1e-6);
  EXPECT_NEAR(fz_sum / n, weight, 0.005 * weight);
  EXPECT_NEAR(az_sum / n, sim.robot().gravity_mps2, 0.01);
  EXPECT_NEAR(gt.q[1], 0.40, 0.005);
  EXPECT_LT(std::abs(gt.q[2]), 0.01);
  EXPECT_EQ(sim.stats().liftoffs[0] + sim.stats().liftoffs[1], 0u);
  EXPECT_EQ(sim.stats().body_contact_steps, 0u);
  EXPECT_EQ(sim.stats().ode_messages, 0u);
  for (int leg = 0; leg < 2; ++leg) EXPECT_GT(gt.lti[static_cast<std::size_t>(leg)], 0.7);
}

INSTANTIATE_TEST_SUITE_P(Substeps, SimStanding, ::testing::Values(1, 2));

TEST(SimReset, StandingPoseIsSettledAndConsistentWithTheModel) {
  Simulator sim(test::robot(), test::options(), Terrain::flat());
  sim.reset(stance());
  const VectorQ q0 = sim.groundTruth().q;
  EXPECT_NEAR(q0[1], 0.40, 1e-12);
  // The sim's q fed to the model puts the model's feet on the sim's ankles.
  const auto model = mft::model::buildBipedModel(sim.robot());
  mft::model::ModelData data;
  mft::model::updateModel(model, q0, VectorQ::Zero(), &data);
  for (int leg = 0; leg < 2; ++leg) {
    EXPECT_NEAR(data.foot_pos[2 * leg], sim.anklePosition(leg).x(), 1e-12);
    EXPECT_NEAR(data.foot_pos[2 * leg + 1], sim.anklePosition(leg).y(), 1e-12);
  }
  EXPECT_LT(data.closure_error.norm(), 1e-12);
  // The same configuration as the model's own closed-loop solver.
  const VectorQ qm = mft::model::closedLoopConfiguration(sim.robot(), Eigen::Vector3d(0.0, 0.40, 0.0),
                                                          Eigen::Vector2d(0.06, sim.anklePosition(0).y() - 0.40),
                                                          Eigen::Vector2d(-0.06, sim.anklePosition(1).y() - 0.40));
  EXPECT_LT((qm - q0).norm(), 1e-9);
  EXPECT_TRUE(sim.sensors().contact[0] && sim.sensors().contact[1]);
  // No drop: the first step already carries the weight, and under the stance controller the base neither sinks
  // nor rises by more than 3 mm (the feed-forward ignores how the legs' own weight is shared).
  test::StanceController ctrl(sim.robot(), q0);
  const double weight = sim.robot().totalMass() * sim.robot().gravity_mps2;
  double lowest = 0.0, highest = 0.0;
  for (int k = 0; k < 300; ++k) {
    sim.setCommand(ctrl.command(sim.sensors()));
    sim.step();
    if (k == 0) {
      const auto& f = sim.groundTruth().contact_force;
      std::cout << "first step: sum Fz / mg = " << (f[1] + f[3]) / weight << "\n";
      EXPECT_NEAR(f[1] + f[3], weight, 0.15 * weight);
    }
    lowest = std::min(lowest, sim.groundTruth().q[1] - q0[1]);
    highest = std::max(highest, sim.groundTruth().q[1] - q0[1]);
  }
  std::cout << "base height change in the first 300 ms after reset: " << lowest << " .. " << highest << " m\n";
  EXPECT_GT(lowest, -0.0005);
  EXPECT_LT(highest, 0.003);
}

TEST(SimReset, EncodersMatchGroundTruthAndReadBack) {
  Simulator sim(test::robot(), test::options(), Terrain::flat());
  sim.reset(stance());
  const auto& s = sim.sensors();
  const auto& gt = sim.groundTruth();
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(s.actuated_pos[static_cast<std::size_t>(i)], gt.q[mft::model::kActuatedIndex[static_cast<std::size_t>(i)]]);
    EXPECT_DOUBLE_EQ(s.passive_pos[static_cast<std::size_t>(i)], gt.q[mft::model::kPassiveIndex[static_cast<std::size_t>(i)]]);
  }
  EXPECT_NEAR(s.accel[1], sim.robot().gravity_mps2, 1e-9);
  // Reset twice gives the same state bit for bit.
  const auto h = sim.stateHash();
  sim.step();
  sim.reset(stance());
  EXPECT_EQ(sim.stateHash(), h);
}
