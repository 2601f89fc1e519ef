// Pushes: an impulse J on the free torso changes the robot's momentum by exactly J; lift-off trigger.
#include <gtest/gtest.h>

#include "sim_test_support.hpp"

using namespace mft::sim;
using mft::model::VectorQ;

TEST(SimImpulse, ChangesMomentumByJ) {
  for (int substeps : {1, 4}) {
    auto o = test::options();
    o.substeps = substeps;
    Simulator sim(test::robot(), o, Terrain::flat());
    StandingPose pose;
    pose.base_height_m = 2.0;  // in the air: no contacts
    pose.leg_length_m = 0.40;
    pose.settle = false;
    sim.reset(pose);
    const double mass = sim.robot().totalMass(), g = sim.robot().gravity_mps2;
    const Eigen::Vector2d J(5.0, 1.5);
    sim.scheduleImpulse({J, ImpulseTrigger::AtTime, 0.0105, 0});
    const Eigen::Vector2d p0 = sim.linearMomentum();
    for (int k = 0; k < 30; ++k) sim.step();
    const Eigen::Vector2d dp = sim.linearMomentum() - p0;
    ASSERT_EQ(sim.stats().impulses.size(), 1u);
    EXPECT_GE(sim.stats().impulses[0].time_s, 0.0105 - 1e-12);
    EXPECT_LT(sim.stats().impulses[0].time_s, 0.0105 + sim.physicsStep());
    // Gravity is the only other external force; joints conserve momentum.
    std::cout << "substeps " << substeps << ": dp - J - gravity = "
              << (dp - J - Eigen::Vector2d(0.0, -mass * g * sim.time())).transpose() << " N s\n";
    EXPECT_NEAR(dp.x(), J.x(), 1e-9);
    EXPECT_NEAR(dp.y(), J.y() - mass * g * sim.time(), 1e-9);
  }
}

TEST(SimImpulse, AppliedAtTheNextLiftOffOfTheChosenLeg) {
  Simulator sim(test::robot(), test::options(), Terrain::flat());
  StandingPose pose;
  pose.foot_offset_x_m = {0.06, -0.06};
  sim.reset(pose);
  test::StanceController ctrl(sim.robot(), sim.groundTruth().q);
  sim.scheduleImpulse({Eigen::Vector2d(2.0, 0.0), ImpulseTrigger::AtLiftOff, 0.0, 1});
  for (int k = 0; k < 100; ++k) {
    sim.setCommand(ctrl.command(sim.sensors()));
    sim.step();
  }
  EXPECT_TRUE(sim.stats().impulses.empty());  // standing: no lift-off, no push
  // Lift the left foot: pull its hips together (the leg shortens).
  for (int k = 0; k < 200 && sim.stats().impulses.empty(); ++k) {
    auto c = ctrl.command(sim.sensors());
    c.tau[2] = -30.0;
    c.tau[3] = 30.0;
    sim.setCommand(c);
    sim.step();
  }
  ASSERT_EQ(sim.stats().impulses.size(), 1u);
  EXPECT_EQ(sim.stats().liftoffs[1], 1u);
  // Applied in the physics step right after the one in which the foot left the ground.
  EXPECT_DOUBLE_EQ(sim.stats().impulses[0].time_s, sim.stats().last_liftoff_time_s[1]);
  std::cout << "left lift-off at " << sim.stats().last_liftoff_time_s[1] << " s, push at "
            << sim.stats().impulses[0].time_s << " s\n";
}
