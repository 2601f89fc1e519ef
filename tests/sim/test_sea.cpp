// Series elastic actuators: settling time, limits, damping mode.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/sea_actuator.hpp"
#include "sim_test_support.hpp"

using namespace mft::sim;

TEST(SimSea, StepResponseSettlesInTs) {
  const auto d = test::robot();
  const double ts = seaSettlingTime(d.actuator.sea.natural_frequency_radps, d.actuator.sea.damping_ratio, 1e-5);
  std::cout << "SEA 2 % settling time (h = 1e-5): " << ts << " s\n";
  EXPECT_NEAR(ts, d.actuator.sea.settling_time_s, 0.1 * d.actuator.sea.settling_time_s);
  // The exact discretisation does not depend on the step.
  EXPECT_NEAR(seaSettlingTime(d.actuator.sea.natural_frequency_radps, d.actuator.sea.damping_ratio, 1e-3), ts, 1e-3);
}

TEST(SimSea, SimulatorSensorSettlesInTs) {
  // Torso fixed in the air, a 10 N m step on the right rear hip: the measured SEA torque settles within 2 %
  // in t_s +- 10 %, sampled at the 1 ms control rate.
  auto o = test::options();
  o.fix_torso = true;
  o.actuator_model = ActuatorModel::Sea;  // the filter model (sea_motor's free thigh: test_sea_motor.cpp)
  Simulator sim(test::robot(), o, Terrain::flat());
  test::hangAndDriveRightHips(sim, 1.0, 10.0, 0.0);
  double last_outside = 0.0;
  for (int k = 0; k < 40; ++k) {  // before the swinging leg nears the speed limit or a stop
    sim.step();
    if (std::abs(sim.sensors().sea_torque[0] - 10.0) > 0.2) last_outside = sim.time();
    EXPECT_LE(sim.sensors().sea_torque[0], 10.0 + 1e-9);  // zeta = 1: no overshoot
  }
  std::cout << "SEA torque sensor outside 2 % until " << last_outside << " s\n";
  const double ts = sim.robot().actuator.sea.settling_time_s;
  EXPECT_GE(last_outside + 0.001, 0.9 * ts);
  EXPECT_LE(last_outside + 0.001, 1.1 * ts);
}

TEST(SimSea, TorqueAndSpeedLimits) {
  const SeaLimits lim{52.36, 20.0, 2.0};
  SeaActuator sea(233.5, 1.0, 1e-3, lim);
  EXPECT_DOUBLE_EQ(sea.limitedInput(100.0, 0.0), 52.36);
  EXPECT_DOUBLE_EQ(sea.limitedInput(-100.0, 0.0), -52.36);
  EXPECT_DOUBLE_EQ(sea.limitedInput(30.0, 17.0), 30.0);   // below the fade band
  EXPECT_DOUBLE_EQ(sea.limitedInput(30.0, 19.0), 15.0);   // half way through the band
  EXPECT_DOUBLE_EQ(sea.limitedInput(30.0, 21.0), 0.0);    // beyond the speed limit: no drive
  EXPECT_DOUBLE_EQ(sea.limitedInput(-30.0, 21.0), -30.0); // braking is always allowed
  for (int k = 0; k < 200; ++k) sea.advance(sea.limitedInput(1e3, 0.0));
  EXPECT_NEAR(sea.torque(), 52.36, 1e-9);
}

TEST(SimSea, SpeedLimitHoldsInSimulation) {
  // A free-swinging leg driven hard: beyond the output speed limit the drive never pushes in the direction of
  // motion (the SEA torque acting on the joint). Gravity and momentum may carry the frictionless leg a little
  // further.
  auto o = test::options();
  o.fix_torso = true;
  o.link_collisions = false;
  o.actuator_model = ActuatorModel::Sea;  // the filter model's output limit (sea_motor: test_sea_motor.cpp)
  Simulator sim(test::robot(), o, Terrain::flat());
  test::hangAndDriveRightHips(sim, 2.0, 50.0, 50.0);  // both right hips forward: the whole leg spins up
  const double limit = sim.robot().actuator.output_speed_limit_radps;
  double max_rate = 0.0;
  // Until the rear hip nears its stop (an impact on a stop makes the other thigh's rate jump).
  for (int k = 0; k < 150 && sim.groundTruth().q[mft::model::hipRearIndex(0)] < 0.25; ++k) {
    const double w_before[2] = {sim.groundTruth().qd[3], sim.groundTruth().qd[5]};
    sim.step();
    for (int i = 0; i < 2; ++i) {
      const double w = sim.groundTruth().qd[mft::model::kActuatedIndex[static_cast<std::size_t>(i)]];
      max_rate = std::max(max_rate, std::abs(w));
      // The torque of a step is set from the rate at its start.
      if (std::abs(w_before[i]) >= limit) {
        EXPECT_LE(sim.sensors().sea_torque[static_cast<std::size_t>(i)] * w_before[i], 0.0);
      }
    }
  }
  std::cout << "max hip rate with 50 N m: " << max_rate << " rad/s (limit " << limit << ")\n";
  EXPECT_LT(max_rate, 1.1 * limit);
}

TEST(SimSea, DampingModeOpposesMotion) {
  auto o = test::options();
  o.fix_torso = true;
  Simulator sim(test::robot(), o, Terrain::flat());
  mft::model::ActuatorCommand c = test::hangAndDriveRightHips(sim, 1.0, 20.0, 20.0);
  for (int k = 0; k < 40; ++k) sim.step();
  const double rate = sim.groundTruth().qd[mft::model::hipRearIndex(0)];
  ASSERT_GT(rate, 1.0);
  c.mode = mft::model::CommandMode::Damping;
  c.tau << 99.0, 99.0, 99.0, 99.0;  // ignored in damping mode
  sim.setCommand(c);
  for (int k = 0; k < 60; ++k) sim.step();
  const double r = sim.groundTruth().qd[mft::model::hipRearIndex(0)];
  EXPECT_LT(sim.sensors().sea_torque[0] * r, 0.0 + 1e-12);  // the drive brakes
  EXPECT_LT(std::abs(r), std::abs(rate));
}
