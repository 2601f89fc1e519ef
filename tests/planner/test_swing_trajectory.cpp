// Cubic swing trajectory: boundary conditions, derivatives against finite differences, late-touchdown descent.
#include <gtest/gtest.h>

#include "planner/swing_trajectory.hpp"

using namespace mft::planner;

namespace {
SwingSpec spec() {
  SwingSpec s;
  s.liftoff = {-0.10, 0.01};
  s.target_x = 0.18;
  s.ground_z = 0.0;
  s.duration_s = 0.35;
  s.lift_height_m = 0.06;
  s.touchdown_speed_mps = 0.2;
  return s;
}
}  // namespace

TEST(CubicHermite, HitsBothEndsWithTheGivenVelocities) {
  const double T = 0.4;
  const auto a = cubicHermite(1.0, -0.5, 2.0, 0.3, T, 0.0);
  const auto b = cubicHermite(1.0, -0.5, 2.0, 0.3, T, T);
  EXPECT_NEAR(a.pos, 1.0, 1e-14);
  EXPECT_NEAR(a.vel, -0.5, 1e-14);
  EXPECT_NEAR(b.pos, 2.0, 1e-12);
  EXPECT_NEAR(b.vel, 0.3, 1e-12);
}

TEST(SwingTrajectory, BoundaryConditions) {
  const SwingSpec s = spec();
  const double T = s.duration_s;
  const auto start = evaluateSwing(s, 0.0);
  EXPECT_NEAR(start.pos.x(), s.liftoff.x(), 1e-14);
  EXPECT_NEAR(start.pos.y(), s.liftoff.y(), 1e-14);
  EXPECT_NEAR(start.vel.norm(), 0.0, 1e-14);

  const auto apex = evaluateSwing(s, 0.5 * T);
  EXPECT_NEAR(apex.pos.y(), s.liftoff.y() + s.lift_height_m, 1e-12);  // apex above the higher of lift-off/ground
  EXPECT_NEAR(apex.vel.y(), 0.0, 1e-12);
  EXPECT_NEAR(apex.pos.x(), 0.5 * (s.liftoff.x() + s.target_x), 1e-12);  // cubic with zero end rates is symmetric

  const auto end = evaluateSwing(s, T);
  EXPECT_NEAR(end.pos.x(), s.target_x, 1e-12);
  EXPECT_NEAR(end.vel.x(), 0.0, 1e-12);
  EXPECT_NEAR(end.pos.y(), s.ground_z, 1e-12);
  EXPECT_NEAR(end.vel.y(), -s.touchdown_speed_mps, 1e-12);
}

TEST(SwingTrajectory, VelocityAndAccelerationMatchFiniteDifferences) {
  const SwingSpec s = spec();
  const double h = 1e-6;
  for (double t = 0.003; t < s.duration_s + 0.1; t += 0.0137) {
    if (std::abs(t - 0.5 * s.duration_s) < 2 * h || std::abs(t - s.duration_s) < 2 * h) continue;  // knots
    const auto m = evaluateSwing(s, t - h), c = evaluateSwing(s, t), p = evaluateSwing(s, t + h);
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(c.vel[k], (p.pos[k] - m.pos[k]) / (2 * h), 1e-7) << "t=" << t << " axis " << k;
      EXPECT_NEAR(c.acc[k], (p.vel[k] - m.vel[k]) / (2 * h), 1e-5) << "t=" << t << " axis " << k;
    }
  }
}

TEST(SwingTrajectory, PositionAndVelocityAreContinuousAtTheKnots) {
  const SwingSpec s = spec();
  const double e = 1e-9;
  for (double knot : {0.5 * s.duration_s, s.duration_s}) {
    const auto a = evaluateSwing(s, knot - e), b = evaluateSwing(s, knot + e);
    EXPECT_NEAR((a.pos - b.pos).norm(), 0.0, 1e-8);
    EXPECT_NEAR((a.vel - b.vel).norm(), 0.0, 1e-6);
  }
}

TEST(SwingTrajectory, LateTouchdownKeepsDescending) {
  const SwingSpec s = spec();
  const auto late = evaluateSwing(s, s.duration_s + 0.05);
  EXPECT_NEAR(late.pos.x(), s.target_x, 1e-12);
  EXPECT_NEAR(late.vel.x(), 0.0, 1e-12);
  EXPECT_NEAR(late.pos.y(), s.ground_z - 0.05 * s.touchdown_speed_mps, 1e-12);
  EXPECT_NEAR(late.vel.y(), -s.touchdown_speed_mps, 1e-12);
}

TEST(SwingTrajectory, StaysAboveGroundUntilTheEnd) {
  const SwingSpec s = spec();
  for (double t = 0.0; t < s.duration_s - 1e-9; t += 0.001) EXPECT_GE(evaluateSwing(s, t).pos.y(), s.ground_z - 1e-12) << t;
}
