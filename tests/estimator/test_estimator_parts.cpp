// Parts of the estimator: leg kinematics, force-based contact, the pitch filter, the configuration file.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/contact_detector.hpp"
#include "estimator/estimator_config.hpp"
#include "estimator/leg_kinematics.hpp"
#include "estimator/pitch_filter.hpp"
#include "common/strict_yaml.hpp"
#include "tests/support/config_test_support.hpp"

using namespace mft;
using namespace mft::estimator;

namespace {
model::RobotDescription robot() { return model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }
std::string configPath() { return std::string(MFT_CONFIG_DIR) + "/estimator.yaml"; }
LegJoints jointsAt(const model::FiveBarGeometry& g, const Eigen::Vector2d& foot) {
  model::FiveBarPose p;
  EXPECT_EQ(model::fiveBarInverse(g, foot, &p), model::FiveBarStatus::Ok);
  LegJoints j;
  j.pos = model::legCoordinates(p);
  return j;
}
}  // namespace

TEST(LegKinematics, FootMatchesTheFiveBarForwardKinematics) {
  const auto g = model::FiveBarGeometry::from(robot());
  for (const Eigen::Vector2d& foot : {Eigen::Vector2d(0.0, -0.42), Eigen::Vector2d(0.08, -0.35), Eigen::Vector2d(-0.1, -0.3)}) {
    const LegJoints j = jointsAt(g, foot);
    model::FiveBarPose fk;
    ASSERT_EQ(model::fiveBarForward(g, j.pos[0], j.pos[2], &fk), model::FiveBarStatus::Ok);
    EXPECT_NEAR((footInBase(g, j).pos - fk.foot).norm(), 0.0, 1e-12);
    EXPECT_NEAR((footInBase(g, j).pos - foot).norm(), 0.0, 1e-12);
  }
}

TEST(LegKinematics, VelocityMatchesFiniteDifferences) {
  const auto g = model::FiveBarGeometry::from(robot());
  const Eigen::Vector2d foot(0.05, -0.38), foot_vel(0.3, -0.2);
  const double h = 1e-6;
  LegJoints j = jointsAt(g, foot);
  const LegJoints jp = jointsAt(g, foot + h * foot_vel), jm = jointsAt(g, foot - h * foot_vel);
  for (int i = 0; i < 4; ++i) j.vel[i] = (jp.pos[i] - jm.pos[i]) / (2 * h);
  EXPECT_NEAR((footInBase(g, j).vel - foot_vel).norm(), 0.0, 1e-7);
}

TEST(LegKinematics, SensorArraysMapToTheLegs) {
  model::SensorReadings s;
  s.actuated_pos = {1, 2, 3, 4};  // [q4, q6, q8, q10]
  s.passive_pos = {5, 6, 7, 8};   // [q5, q7, q9, q11]
  const auto left = legJoints(s, model::kLeftLeg);
  EXPECT_EQ(left.pos, (std::array<double, 4>{3, 7, 4, 8}));  // [q8, q9, q10, q11]
}

TEST(ContactDetector, QuasiStaticForceRecoversTheGroundForce) {
  const auto g = model::FiveBarGeometry::from(robot());
  const LegJoints j = jointsAt(g, {0.03, -0.40});
  model::FiveBarPose pose;
  model::fiveBarForward(g, j.pos[0], j.pos[2], &pose);
  const Eigen::Vector2d f(15.0, 110.0);  // ground on foot
  const Eigen::Vector2d tau = -model::fiveBarFootJacobian(g, pose).transpose() * f;
  Eigen::Vector2d est;
  ASSERT_TRUE(estimateFootForce(g, j.pos[0], j.pos[2], tau, &est));
  EXPECT_NEAR((est - f).norm(), 0.0, 1e-9);
}

TEST(ContactDetector, ForceContactHasHysteresisAndSourcesCombine) {
  const auto g = model::FiveBarGeometry::from(robot());
  ContactParams p;
  p.source = ContactSource::Force;
  p.force_on_N = 60;
  p.force_off_N = 30;
  ContactDetector det(p, g);
  const LegJoints j = jointsAt(g, {0.0, -0.40});
  model::FiveBarPose pose;
  model::fiveBarForward(g, j.pos[0], j.pos[2], &pose);
  auto readings = [&](double fz, bool sw) {
    model::SensorReadings s;
    const Eigen::Vector2d tau = -model::fiveBarFootJacobian(g, pose).transpose() * Eigen::Vector2d(0, fz);
    for (int leg = 0; leg < 2; ++leg) {
      s.actuated_pos[2 * leg] = j.pos[0];
      s.actuated_pos[2 * leg + 1] = j.pos[2];
      s.sea_torque[2 * leg] = tau[0];
      s.sea_torque[2 * leg + 1] = tau[1];
      s.contact[leg] = sw;
    }
    return s;
  };
  EXPECT_FALSE(det.update(readings(50, true), 0.0)[0]);  // below on
  EXPECT_TRUE(det.update(readings(70, false), 0.0)[0]);  // above on
  EXPECT_NEAR(det.force()[0].y(), 70.0, 1e-9);
  EXPECT_TRUE(det.update(readings(40, false), 0.0)[0]);  // between: stays
  EXPECT_FALSE(det.update(readings(20, false), 0.0)[0]); // below off

  p.source = ContactSource::Switch;
  EXPECT_TRUE(ContactDetector(p, g).update(readings(0, true), 0.0)[1]);
  p.source = ContactSource::Both;
  EXPECT_FALSE(ContactDetector(p, g).update(readings(100, false), 0.0)[1]);
  p.source = ContactSource::Either;
  EXPECT_TRUE(ContactDetector(p, g).update(readings(100, false), 0.0)[1]);
}

TEST(PitchFilter, TiltFromSpecificForce) {
  const double g = 9.81, th = 0.2;
  // At rest the accelerometer reads R' (0, g): nose up gives a positive x reading.
  const Eigen::Vector2d f(g * std::sin(th), g * std::cos(th));
  EXPECT_NEAR(tiltFromSpecificForce(f, Eigen::Vector2d::Zero(), g), th, 1e-12);
  // Accelerating forward at a, level: reads (a, g); with the acceleration known the tilt is still 0.
  EXPECT_NEAR(tiltFromSpecificForce({1.5, g}, {1.5, 0.0}, g), 0.0, 1e-12);
}

TEST(PitchFilter, CorrectsAnInitialErrorAndEstimatesTheGyroBias) {
  PitchParams p;
  p.correction_time_constant_s = 1.0;
  p.gyro_bias_gain = 0.25;
  PitchFilter f(p, 9.81);
  f.reset(0.1);  // true pitch 0.05, gyro bias 0.03
  const double th = 0.05;
  const Eigen::Vector2d fb(9.81 * std::sin(th), 9.81 * std::cos(th));
  for (int i = 0; i < 30000; ++i) f.update(0.03, fb, Eigen::Vector2d::Zero(), 0.001);
  EXPECT_NEAR(f.pitch(), th, 1e-4);
  EXPECT_NEAR(f.gyroBias(), 0.03, 1e-4);
  EXPECT_TRUE(f.correctionUsed());
  // An impact (specific force far from g) is gated out.
  f.update(0.0, {40.0, 60.0}, Eigen::Vector2d::Zero(), 0.001);
  EXPECT_FALSE(f.correctionUsed());
}

TEST(EstimatorConfig, DefaultFileLoads) {
  const auto c = loadEstimatorConfig(configPath());
  EXPECT_EQ(c.mode, EstimatorMode::Kalman);
  EXPECT_EQ(c.contact.source, ContactSource::Switch);
  EXPECT_EQ(c.source_file, configPath());
}

namespace {
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  mft::test::expectConfigError(mft::test::readTextFile(configPath()), pattern, replacement, "bad-estimator.yaml",
                               expect, parseEstimatorConfig);
}
}  // namespace

TEST(EstimatorConfig, ErrorsNameFileAndKey) {
  expectError(R"(\n  kinematic_position_std_m: [^\n]*)", "", "kalman.kinematic_position_std_m: missing key");
  expectError(R"(  ground_height_m: 0.0)", "  ground_height_m: 0.0\n  ground_slope: 0", "unknown key kalman.ground_slope");
  expectError(R"(mode: kalman)", "mode: magic", "mode: expected kalman or ground_truth");
  expectError(R"(source: switch)", "source: radar", "contact.source: expected switch, force, either or both");
  expectError(R"(force_off_N: 30.0)", "force_off_N: 80.0", "contact.force_off_N: must be <= force_on_N");
  expectError(R"(use_ground_height: true)", "use_ground_height: maybe", "kalman.use_ground_height: expected true or false");
  expectError(R"(correction_time_constant_s: 1.0)", "correction_time_constant_s: -1", "pitch.correction_time_constant_s: must be > 0");
  expectError(R"(max_dt_s: 0.02)", "max_dt_s: 0.0001", "timing.max_dt_s: must be >= nominal_dt_s");
}

TEST(EstimatorConfig, MissingFileIsAClearError) {
  try {
    loadEstimatorConfig("/nonexistent/estimator.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/estimator.yaml: cannot open the file"), std::string::npos);
  }
}
