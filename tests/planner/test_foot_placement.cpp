// LIP prediction against an independent integration and the closed form, H-LIP desired speed, eq. 13 numbers.
#include <gtest/gtest.h>

#include <cmath>

#include "planner/foot_placement.hpp"

using namespace mft::planner;

TEST(Lip, PredictionMatchesTheClosedForm) {
  const double g = 9.81, h = 0.45, lambda = std::sqrt(g / h);
  EXPECT_DOUBLE_EQ(lipLambda(g, h), lambda);
  const LipState x0{-0.04, 0.35};
  const double t = 0.21;
  // x(t) = (x0 + xd0/l)/2 e^{lt} + (x0 - xd0/l)/2 e^{-lt}
  const double a = 0.5 * (x0.x + x0.xd / lambda), b = 0.5 * (x0.x - x0.xd / lambda);
  const LipState p = lipPredict(x0, lambda, t);
  EXPECT_NEAR(p.x, a * std::exp(lambda * t) + b * std::exp(-lambda * t), 1e-14);
  EXPECT_NEAR(p.xd, lambda * (a * std::exp(lambda * t) - b * std::exp(-lambda * t)), 1e-14);
}

TEST(Lip, PredictionMatchesNumericalIntegration) {
  const double lambda = lipLambda(9.81, 0.42);
  LipState s{0.03, -0.2};
  const LipState pred = lipPredict(s, lambda, 0.35);
  const int n = 3500;
  const double dt = 0.35 / n;
  auto f = [&](const LipState& y) { return LipState{y.xd, lambda * lambda * y.x}; };
  for (int i = 0; i < n; ++i) {  // RK4
    const LipState k1 = f(s);
    const LipState k2 = f({s.x + 0.5 * dt * k1.x, s.xd + 0.5 * dt * k1.xd});
    const LipState k3 = f({s.x + 0.5 * dt * k2.x, s.xd + 0.5 * dt * k2.xd});
    const LipState k4 = f({s.x + dt * k3.x, s.xd + dt * k3.xd});
    s.x += dt / 6 * (k1.x + 2 * k2.x + 2 * k3.x + k4.x);
    s.xd += dt / 6 * (k1.xd + 2 * k2.xd + 2 * k3.xd + k4.xd);
  }
  EXPECT_NEAR(pred.x, s.x, 1e-12);
  EXPECT_NEAR(pred.xd, s.xd, 1e-12);
}

TEST(Lip, ConservesOrbitalEnergy) {
  const double lambda = lipLambda(9.81, 0.45);
  const LipState s0{0.05, 0.3};
  const LipState s1 = lipPredict(s0, lambda, 0.3);
  auto energy = [&](const LipState& s) { return s.xd * s.xd - lambda * lambda * s.x * s.x; };
  EXPECT_NEAR(energy(s0), energy(s1), 1e-12);
}

TEST(Hlip, PeriodOneOrbitReproducesTheAverageSpeed) {
  // Start a step at x = -u/2 with the orbit's speed; after T the CoM is at +u/2 with the same speed: the
  // average speed is u / T.
  const double lambda = lipLambda(9.81, 0.45), T = 0.35, v_avg = 0.4;
  const double v_minus = hlipPreImpactSpeed(v_avg, lambda, T, 0.0);
  const double u = v_avg * T;
  const double x_minus = u / 2;
  // Symmetric orbit: velocity at -u/2 equals velocity at +u/2.
  const LipState end = lipPredict({-x_minus, v_minus}, lambda, T);
  EXPECT_NEAR(end.x, x_minus, 1e-12);
  EXPECT_NEAR(end.xd, v_minus, 1e-12);
  EXPECT_NEAR(v_minus, v_avg * lambda * T / 2 / std::tanh(lambda * T / 2), 1e-12);
  EXPECT_DOUBLE_EQ(hlipPreImpactSpeed(0.0, lambda, T, 0.0), 0.0);
}

TEST(Hlip, DoubleSupportVersionKeepsTheAverageSpeed) {
  // With double support T_d (CoM at constant speed v-), one period is: SSP from -x0 to x-, DSP covers v- T_d.
  const double lambda = lipLambda(9.81, 0.45), T = 0.35, Td = 0.05, v_avg = 0.3;
  const double v_minus = hlipPreImpactSpeed(v_avg, lambda, T, Td);
  const double sigma1 = lambda / std::tanh(lambda * T / 2);
  const double x_minus = v_minus / sigma1;
  const double u = v_avg * (T + Td);
  const double x_plus = x_minus + v_minus * Td - u;  // relative to the new stance foot after the DSP
  const LipState end = lipPredict({x_plus, v_minus}, lambda, T);
  EXPECT_NEAR(end.x, x_minus, 1e-12);
  EXPECT_NEAR(end.xd, v_minus, 1e-12);
}

TEST(Eq13, FootPlacementNumbers) {
  FootPlacementParams p;  // paper: k_v = 0.16, k_p = 0.08
  p.k_v = 0.16;
  p.k_p = 0.08;
  p.max_offset_m = 0.25;
  // x = 0.05 + 0.16 * 0.4 + 0.08 * (0.4 - 0.3) = 0.122
  EXPECT_NEAR(footPlacement(0.05, 0.4, 0.3, p), 0.122, 1e-15);
  // Standing still at the desired speed 0: the foot goes under the CoM.
  EXPECT_NEAR(footPlacement(1.3, 0.0, 0.0, p), 1.3, 1e-15);
  // Moving backward faster than desired: step back. 2.0 + 0.16 (-0.5) + 0.08 (-0.5 - 0) = 1.88
  EXPECT_NEAR(footPlacement(2.0, -0.5, 0.0, p), 1.88, 1e-15);
  // Clamped to the reach.
  EXPECT_NEAR(footPlacement(0.0, 5.0, 0.0, p), 0.25, 1e-15);
  EXPECT_NEAR(footPlacement(0.0, -5.0, 0.0, p), -0.25, 1e-15);
}
