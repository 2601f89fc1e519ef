// Five-bar leg kinematics: IK/FK round trips, the assembly mode, Jacobians and knee rates against central
// finite differences, and the nominal stance numbers of docs/reference/five-bar-theory.md#robot-parameters-and-the-sea.
#include <gtest/gtest.h>

#include <random>

#include "model/five_bar.hpp"

using namespace mft::model;

namespace {
FiveBarGeometry geometries[] = {{0.0, 0.22, 0.26}, {0.06, 0.22, 0.26}, {0.0, 0.18, 0.33}};

// Random reachable foot points of a geometry, away from the workspace boundary.
std::vector<Eigen::Vector2d> randomFeet(const FiveBarGeometry& g, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-0.4, 0.4), uz(-0.6, -0.05);
  std::vector<Eigen::Vector2d> feet;
  while (static_cast<int>(feet.size()) < n) {
    const Eigen::Vector2d c(ux(rng), uz(rng));
    const double dr = (c - g.hipRear()).norm(), df = (c - g.hipFore()).norm();
    const double lo = std::abs(g.l2 - g.l1) + 0.01, hi = g.l1 + g.l2 - 0.01;
    if (dr > lo && dr < hi && df > lo && df < hi) feet.push_back(c);
  }
  return feet;
}
}  // namespace

TEST(FiveBar, NominalStanceMatchesTheDesignNotes) {
  FiveBarPose p;
  ASSERT_EQ(fiveBarInverse(geometries[0], {0.0, -0.40}, &p), FiveBarStatus::Ok);
  EXPECT_NEAR(p.q_rear, -0.6435, 1e-4);
  EXPECT_NEAR(p.q_fore, 0.6435, 1e-4);
  EXPECT_NEAR(p.knee_rear, 1.176, 1e-3);
  EXPECT_NEAR(p.knee_fore, -1.176, 1e-3);
}

TEST(FiveBar, InverseThenForwardRoundTrip) {
  for (const auto& g : geometries) {
    for (const auto& c : randomFeet(g, 2000, 7)) {
      FiveBarPose inv, fwd;
      ASSERT_EQ(fiveBarInverse(g, c, &inv), FiveBarStatus::Ok);
      ASSERT_EQ(fiveBarForward(g, inv.q_rear, inv.q_fore, &fwd), FiveBarStatus::Ok);
      EXPECT_LT((fwd.foot - c).norm(), 1e-12);
      EXPECT_NEAR(wrapAngle(fwd.knee_rear - inv.knee_rear), 0.0, 1e-12);
      EXPECT_NEAR(wrapAngle(fwd.knee_fore - inv.knee_fore), 0.0, 1e-12);
      // Assembly mode: rear knee bends backward, fore knee forward, both shanks reach the foot.
      EXPECT_GT(inv.knee_rear, 0.0);
      EXPECT_LT(inv.knee_fore, 0.0);
      EXPECT_NEAR((c - inv.knee_point_rear).norm(), g.l2, 1e-12);
      EXPECT_NEAR((c - inv.knee_point_fore).norm(), g.l2, 1e-12);
    }
  }
}

TEST(FiveBar, ForwardThenInverseRoundTrip) {
  const auto& g = geometries[0];
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> qr(-1.9, 0.35), qf(-0.35, 1.9);
  int checked = 0;
  for (int k = 0; k < 5000; ++k) {
    FiveBarPose fwd, inv;
    const double a = qr(rng), b = qf(rng);
    if (b - a < 0.05) continue;  // thighs (nearly) coincide or cross: outside the assembly mode
    if (fiveBarForward(g, a, b, &fwd) != FiveBarStatus::Ok) continue;
    if (std::abs(std::sin(fwd.knee_rear)) < 0.05 || std::abs(std::sin(fwd.knee_fore)) < 0.05) continue;
    ASSERT_EQ(fiveBarInverse(g, fwd.foot, &inv), FiveBarStatus::Ok);
    EXPECT_NEAR(inv.q_rear, a, 1e-12);
    EXPECT_NEAR(inv.q_fore, b, 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(FiveBar, UnreachableAndDegenerateCasesAreReported) {
  const auto& g = geometries[0];
  FiveBarPose p;
  EXPECT_EQ(fiveBarInverse(g, {0.0, -0.49}, &p), FiveBarStatus::Unreachable);
  EXPECT_EQ(fiveBarInverse(g, {0.0, -0.03}, &p), FiveBarStatus::Unreachable);
  EXPECT_EQ(fiveBarForward(g, 0.3, 0.3, &p), FiveBarStatus::Degenerate);
  const FiveBarGeometry short_shanks{0.2, 0.22, 0.15};  // knees can be farther apart than two shanks
  EXPECT_EQ(fiveBarForward(short_shanks, -1.5, 1.5, &p), FiveBarStatus::Unreachable);
}

TEST(FiveBar, FootJacobianMatchesFiniteDifferences) {
  for (const auto& g : geometries) {
    for (const auto& c : randomFeet(g, 300, 11)) {
      FiveBarPose p, pp, pm;
      ASSERT_EQ(fiveBarInverse(g, c, &p), FiveBarStatus::Ok);
      const Eigen::Matrix2d J = fiveBarFootJacobian(g, p);
      const double h = 1e-6;
      Eigen::Matrix2d Jfd;
      fiveBarForward(g, p.q_rear + h, p.q_fore, &pp);
      fiveBarForward(g, p.q_rear - h, p.q_fore, &pm);
      Jfd.col(0) = (pp.foot - pm.foot) / (2 * h);
      fiveBarForward(g, p.q_rear, p.q_fore + h, &pp);
      fiveBarForward(g, p.q_rear, p.q_fore - h, &pm);
      Jfd.col(1) = (pp.foot - pm.foot) / (2 * h);
      EXPECT_LT((J - Jfd).norm(), 1e-6 * (1.0 + J.norm()));
    }
  }
}

TEST(FiveBar, KneeRatesMatchFiniteDifferences) {
  const auto& g = geometries[1];
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& c : randomFeet(g, 300, 13)) {
    FiveBarPose p, pp, pm;
    ASSERT_EQ(fiveBarInverse(g, c, &p), FiveBarStatus::Ok);
    const Eigen::Vector2d rates(u(rng), u(rng));
    const double h = 1e-6;
    fiveBarForward(g, p.q_rear + h * rates[0], p.q_fore + h * rates[1], &pp);
    fiveBarForward(g, p.q_rear - h * rates[0], p.q_fore - h * rates[1], &pm);
    const Eigen::Vector2d fd(wrapAngle(pp.knee_rear - pm.knee_rear) / (2 * h), wrapAngle(pp.knee_fore - pm.knee_fore) / (2 * h));
    EXPECT_LT((fiveBarKneeRates(g, p, rates) - fd).norm(), 1e-6);
  }
}
