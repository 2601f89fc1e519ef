// Paper (12), the prediction behind the MFT rows (16e), the SA-WBC rows (20) and the predicted-violation
// diagnostic: one function, checked against a fine numerical integration of constant acceleration.
#include <gtest/gtest.h>

#include <random>

#include "wbc/wbc_formulation.hpp"

namespace mft::wbc {
namespace {

// Position after `dt` under constant `qdd`, by 100 000 midpoint steps (exact for a constant acceleration up to
// rounding, and computed without the closed form).
double integrated(double q, double qd, double qdd, double dt) {
  constexpr int kSteps = 100000;
  const double h = dt / kSteps;
  for (int i = 0; i < kSteps; ++i) {
    const double qd_next = qd + qdd * h;
    q += 0.5 * (qd + qd_next) * h;
    qd = qd_next;
  }
  return q;
}

TEST(Prediction, MatchesTheIntegratedConstantAccelerationMotion) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> q(-2.0, 2.0), qd(-10.0, 10.0), qdd(-200.0, 200.0);
  for (int n = 0; n < 200; ++n) {
    const double q0 = q(rng), v0 = qd(rng), a = qdd(rng);
    for (double dt : {0.001, 0.05, 0.2}) EXPECT_NEAR(predictedCoordinate(q0, v0, a, dt), integrated(q0, v0, a, dt), 1e-9);
  }
}

TEST(Prediction, WithoutAccelerationIsTheLinearPart) {
  // The rows take qdd out as their matrix (C = dt^2/2 A, eq. 13): the rest must be exactly q + qd dt.
  EXPECT_EQ(predictedCoordinate(0.3, -1.25, 0.0, 0.05), 0.3 + -1.25 * 0.05);
  EXPECT_NEAR(predictedCoordinate(0.3, -1.25, 4.0, 0.05) - predictedCoordinate(0.3, -1.25, 0.0, 0.05), 0.5 * 4.0 * 0.05 * 0.05,
              1e-15);
}

}  // namespace
}  // namespace mft::wbc
