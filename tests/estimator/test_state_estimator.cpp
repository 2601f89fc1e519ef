// The estimator on synthetic walking data (known base motion, fixed stance feet, exact IMU), with and without
// noise and gyro bias, and the ground-truth bypass.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/state_estimator.hpp"
#include "synthetic_walk.hpp"

using namespace mft;
using estimator::StateEstimator;

namespace {
model::RobotDescription robot() { return model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }
estimator::EstimatorConfig config() { return estimator::loadEstimatorConfig(std::string(MFT_CONFIG_DIR) + "/estimator.yaml"); }

struct Errors {
  double z_rms = 0, pitch_rms = 0, vx_rms = 0, vz_rms = 0, pitch_rate_rms = 0;
  int n = 0;
  void add(const model::RobotStateEstimate& e, const model::GroundTruthState& t) {
    auto sq = [](double v) { return v * v; };
    z_rms += sq(e.q[1] - t.q[1]);
    pitch_rms += sq(e.q[2] - t.q[2]);
    vx_rms += sq(e.qd[0] - t.qd[0]);
    vz_rms += sq(e.qd[1] - t.qd[1]);
    pitch_rate_rms += sq(e.qd[2] - t.qd[2]);
    ++n;
  }
  void finish() {
    for (double* v : {&z_rms, &pitch_rms, &vx_rms, &vz_rms, &pitch_rate_rms}) *v = std::sqrt(*v / n);
  }
};

// Runs the estimator for `duration` s at 1 kHz from automatic initialization; errors counted after 1 s.
Errors run(const test::WalkOptions& o, double duration, StateEstimator* est = nullptr) {
  const auto d = robot();
  StateEstimator local(config(), d);
  if (est == nullptr) est = &local;
  test::SyntheticWalk walk(d, o);
  Errors err;
  for (int k = 0; k * 0.001 < duration; ++k) {
    const auto s = walk.sample(k * 0.001, k);
    const auto& e = est->updateKalman(s.readings);
    if (k * 0.001 >= 1.0) err.add(e, s.truth);
  }
  err.finish();
  return err;
}

void print(const char* name, const Errors& e) {
  std::printf("%s: z %.2e m, pitch %.2e rad, vx %.2e m/s, vz %.2e m/s, pitch rate %.2e rad/s (RMS)\n", name, e.z_rms,
              e.pitch_rms, e.vx_rms, e.vz_rms, e.pitch_rate_rms);
}
}  // namespace

TEST(StateEstimator, TracksExactSyntheticWalk) {
  const Errors e = run({}, 10.0);
  print("exact", e);
  EXPECT_LT(e.z_rms, 0.005);
  EXPECT_LT(e.pitch_rms, 0.01);
  EXPECT_LT(e.vx_rms, 0.05);
}

TEST(StateEstimator, TracksNoisySyntheticWalkWithGyroBias) {
  test::WalkOptions o;
  o.gyro_std = 0.01;        // rad/s per sample
  o.gyro_bias = 0.02;       // rad/s
  o.accel_std = 0.1;        // m/s^2 per sample
  o.encoder_std = 2e-4;     // rad
  o.encoder_vel_std = 0.02; // rad/s
  StateEstimator est(config(), robot());
  const Errors e = run(o, 20.0, &est);
  print("noisy + gyro bias", e);
  EXPECT_LT(e.z_rms, 0.005);
  EXPECT_LT(e.pitch_rms, 0.01);
  EXPECT_LT(e.vx_rms, 0.05);
  EXPECT_NEAR(est.pitchFilter().gyroBias(), 0.02, 0.01);
}

TEST(StateEstimator, LegCoordinatesComeStraightFromTheEncoders) {
  const auto d = robot();
  StateEstimator est(config(), d);
  test::SyntheticWalk walk(d, {});
  const auto s = walk.sample(0.123, 123);
  const auto& e = est.updateKalman(s.readings);
  EXPECT_EQ(e.tick, 123u);
  EXPECT_DOUBLE_EQ(e.time_s, 0.123);
  for (int i = 0; i < model::kNa; ++i) {
    EXPECT_EQ(e.q[model::kActuatedIndex[i]], s.readings.actuated_pos[i]);
    EXPECT_EQ(e.qd[model::kActuatedIndex[i]], s.readings.actuated_vel[i]);
    EXPECT_EQ(e.q[model::kPassiveIndex[i]], s.readings.passive_pos[i]);
    EXPECT_EQ(e.qd[model::kPassiveIndex[i]], s.readings.passive_vel[i]);
  }
  EXPECT_EQ(e.contact, s.readings.contact);
}

TEST(StateEstimator, AutomaticInitializationFindsHeightAndPitchAtRest) {
  const auto d = robot();
  StateEstimator est(config(), d);
  test::WalkOptions o;
  o.speed = 0.0;
  o.x_amp = o.z_amp = o.pitch_amp = 0.0;
  test::SyntheticWalk walk(d, o);
  auto s = walk.sample(0.0, 0);
  s.readings.contact = {true, true};
  const auto& e = est.updateKalman(s.readings);
  EXPECT_NEAR(e.q[1], 0.42, 1e-9);
  EXPECT_NEAR(e.q[2], 0.0, 1e-9);
  EXPECT_NEAR(e.q[0], 0.0, 1e-9);
}

TEST(StateEstimator, InitializeFromAKnownStateThenTrackX) {
  const auto d = robot();
  StateEstimator est(config(), d);
  test::SyntheticWalk walk(d, {});
  auto s0 = walk.sample(0.0, 0);
  est.initialize(s0.truth.q.head<3>(), s0.truth.qd.head<3>(), s0.readings);
  double max_x_err = 0.0;
  for (int k = 1; k <= 5000; ++k) {
    const auto s = walk.sample(k * 0.001, k);
    const auto& e = est.updateKalman(s.readings);
    max_x_err = std::max(max_x_err, std::abs(e.q[0] - s.truth.q[0]));
  }
  EXPECT_LT(max_x_err, 0.02);  // x is unobservable (drifts only through foot slip noise)
}

TEST(StateEstimator, GroundTruthBypassPassesTruthThroughUnchanged) {
  auto c = config();
  c.mode = estimator::EstimatorMode::GroundTruth;
  const auto d = robot();
  StateEstimator est(c, d);
  test::SyntheticWalk walk(d, {});
  auto s = walk.sample(0.5, 500);
  s.truth.qd[7] = 3.25;  // anything: must come back bit for bit
  s.truth.contact_force << 0.0, 120.0, 0.0, 0.5;
  const auto& e = est.update(s.readings, &s.truth);
  EXPECT_EQ(e.tick, 500u);
  EXPECT_EQ(e.time_s, 0.5);
  EXPECT_EQ(e.q, s.truth.q);
  EXPECT_EQ(e.qd, s.truth.qd);
  EXPECT_TRUE(e.contact[0]);
  EXPECT_FALSE(e.contact[1]);  // 0.5 N is below the 1 N threshold
  EXPECT_THROW(est.update(s.readings, nullptr), std::invalid_argument);
}
