// Hard stops at the hip limits and the knees' singular folds hold against large torques.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_test_support.hpp"

using namespace mft::sim;

TEST(SimHardStops, HoldAgainstFullTorque) {
  auto o = test::options();
  o.fix_torso = true;
  const auto d = test::robot();
  const double m = d.knee_hard_stop_margin_rad;
  const mft::model::Interval limits[4] = {d.rear_hip_rad,
                                          {d.rear_knee_rad.lo + m, d.rear_knee_rad.hi - m},
                                          d.fore_hip_rad,
                                          {d.fore_knee_rad.lo + m, d.fore_knee_rad.hi - m}};
  // Pull each leg's thighs together (stretch: knee stops at 0) and apart (fold: hip limits, knees near pi),
  // and swing both thighs to one side (hip limits).
  const double cases[4][2] = {{40.0, -40.0}, {-40.0, 40.0}, {40.0, 40.0}, {-40.0, -40.0}};
  for (const auto& tau : cases) {
    Simulator sim(d, o, Terrain::flat());
    StandingPose pose;
    pose.base_height_m = 1.5;
    pose.leg_length_m = 0.40;
    sim.reset(pose);
    mft::model::ActuatorCommand c;
    c.tau << tau[0], tau[1], tau[0], tau[1];
    sim.setCommand(c);
    double worst = 0.0, worst_static = 0.0;
    bool touched = false;
    for (int k = 0; k < 1500; ++k) {
      sim.step();
      const auto& q = sim.groundTruth().q;
      for (int leg = 0; leg < 2; ++leg)
        for (int j = 0; j < 4; ++j) {
          const double v = q[3 + 4 * leg + j];
          worst = std::max({worst, limits[j].lo - v, v - limits[j].hi});
          if (k >= 1000) worst_static = std::max({worst_static, limits[j].lo - v, v - limits[j].hi});
          touched = touched || v < limits[j].lo + 0.01 || v > limits[j].hi - 0.01;
        }
    }
    std::cout << "hip torques (" << tau[0] << ", " << tau[1] << "): stop penetration at impact " << worst << " rad, held " << worst_static << " rad, q "
              << sim.groundTruth().q.segment<4>(3).transpose() << "\n";
    EXPECT_TRUE(touched);
    EXPECT_LT(worst, 0.03);         // slamming into the stop with 40 N m
    EXPECT_LT(worst_static, 0.005);  // held against 40 N m
  }
}
