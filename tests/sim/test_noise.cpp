// Sensor noise is seeded: same seed -> same readings; statistics as configured; reset reseeds.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_test_support.hpp"

using namespace mft::sim;

namespace {
SimOptions noisy(std::uint64_t seed) {
  auto o = test::options();
  o.noise.enabled = true;
  o.noise.seed = seed;
  o.noise.gyro_bias_radps = 0.01;
  o.fix_torso = true;
  return o;
}
std::vector<double> record(Simulator& sim, int n) {
  std::vector<double> v;
  StandingPose pose;
  pose.base_height_m = 1.0;
  pose.leg_length_m = 0.40;
  sim.reset(pose);
  for (int k = 0; k < n; ++k) {
    sim.step();
    const auto& s = sim.sensors();
    v.push_back(s.gyro_pitch_rate);
    v.push_back(s.accel[0]);
    v.push_back(s.actuated_pos[0] - sim.groundTruth().q[3]);
    v.push_back(s.sea_torque[1]);
  }
  return v;
}
}  // namespace

TEST(SimNoise, SeededAndAsConfigured) {
  Simulator a(test::robot(), noisy(11), Terrain::flat()), b(test::robot(), noisy(11), Terrain::flat()),
      c(test::robot(), noisy(12), Terrain::flat());
  const auto va = record(a, 2000);
  EXPECT_EQ(va, record(b, 2000));
  EXPECT_EQ(va, record(a, 2000));  // reset reseeds
  EXPECT_NE(va, record(c, 2000));
  // Torso fixed: the gyro reads bias + noise only.
  double mean = 0.0, var = 0.0, enc = 0.0;
  for (std::size_t i = 0; i < va.size(); i += 4) mean += va[i];
  mean /= 2000.0;
  for (std::size_t i = 0; i < va.size(); i += 4) var += (va[i] - mean) * (va[i] - mean), enc += va[i + 2] * va[i + 2];
  const auto& n = a.options().noise;
  EXPECT_NEAR(mean, n.gyro_bias_radps, 4.0 * n.gyro_std_radps / std::sqrt(2000.0));
  EXPECT_NEAR(std::sqrt(var / 1999.0), n.gyro_std_radps, 0.1 * n.gyro_std_radps);
  EXPECT_NEAR(std::sqrt(enc / 2000.0), n.encoder_position_std_rad, 0.1 * n.encoder_position_std_rad);
  // Ground truth stays clean.
  EXPECT_EQ(a.groundTruth().qd[2], 0.0);
}

TEST(SimNoise, DisabledMeansClean) {
  auto o = noisy(3);
  o.noise.enabled = false;
  Simulator sim(test::robot(), o, Terrain::flat());
  sim.step();
  EXPECT_EQ(sim.sensors().gyro_pitch_rate, 0.0);
  EXPECT_EQ(sim.sensors().actuated_pos[2], sim.groundTruth().q[7]);
}
