// Paper (1)-(4): the transmission angle (1) and the limb powers (2) against closed forms, and the LTI closed forms
// of docs/reference/five-bar-theory.md#transmission-indices-lti against an independent screw-theory computation
// (reciprocal products of the transmission wrench with the input and output twists, maxima by sampling force
// directions), and singular configurations giving 0 without NaN. The test keeps its own planar screw types as
// the oracle; the library's (2) is checked against them and against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "model/mft_criteria.hpp"
#include "model/mft_indices.hpp"

using namespace mft::model;

namespace {

// Planar screws in the (x, z) plane, CCW positive: twist (w; v at the origin), wrench (f; moment at the origin).
struct Twist {
  double w;
  Eigen::Vector2d v;
};
struct Wrench {
  Eigen::Vector2d f;
  double m;
};
// Unit rotation about P: a point X moves with w * perp(X - P); at the origin v = perp(-P).
Twist rotationAbout(const Eigen::Vector2d& P) { return {1.0, Eigen::Vector2d(P.y(), -P.x())}; }
// Pure force of direction f on a line through Q.
Wrench forceThrough(const Eigen::Vector2d& Q, const Eigen::Vector2d& f) { return {f, Q.x() * f.y() - Q.y() * f.x()}; }
double reciprocal(const Wrench& W, const Twist& T) { return W.f.dot(T.v) + W.m * T.w; }

// max over unit force directions through Q of |W o T|: sampled, then refined around the best angle.
double maxPower(const Eigen::Vector2d& Q, const Twist& T) {
  auto p = [&](double a) { return std::abs(reciprocal(forceThrough(Q, {std::cos(a), std::sin(a)}), T)); };
  double best_a = 0.0, best = -1.0;
  for (int i = 0; i < 720; ++i) {
    const double a = M_PI * i / 720.0;
    if (p(a) > best) best = p(a), best_a = a;
  }
  for (double h = M_PI / 720.0; h > 1e-12; h *= 0.5)
    for (double a : {best_a - h, best_a + h})
      if (p(a) > best) best = p(a), best_a = a;
  return best;
}

const FiveBarGeometry kGeometries[] = {{0.0, 0.22, 0.26}, {0.06, 0.22, 0.26}, {0.0, 0.18, 0.33}, {0.04, 0.30, 0.25}};

// Calls check(geometry, pose) for `per_geometry` reachable random poses (hips in [-1.9, 1.9]) of every geometry.
template <class Check>
void forRandomPoses(unsigned seed, int per_geometry, Check&& check) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> q(-1.9, 1.9);
  for (const auto& g : kGeometries) {
    for (int n = 0; n < per_geometry;) {
      FiveBarPose p;
      if (fiveBarForward(g, q(rng), q(rng), &p) != FiveBarStatus::Ok) continue;
      ++n;
      check(g, p);
    }
  }
}

}  // namespace

TEST(MftIndices, ClosedFormsMatchScrewTheory) {
  int checked = 0;
  forRandomPoses(11, 400, [&checked](const FiveBarGeometry& g, const FiveBarPose& p) {
    const Eigen::Vector2d A[2] = {g.hipRear(), g.hipFore()};
    const Eigen::Vector2d B[2] = {p.knee_point_rear, p.knee_point_fore};
    const Eigen::Vector2d C = p.foot;
    double lambda[2], eta[2];
    for (int i = 0; i < 2; ++i) {
      const int j = 1 - i;
      // Transmission wrench of chain i: a pure force along the shank (two passive revolutes), through C.
      const Wrench T = forceThrough(C, (C - B[i]).normalized());
      const Twist in = rotationAbout(A[i]);   // input twist: the actuated hip
      const Twist out = rotationAbout(B[j]);  // output twist: other hip locked, foot turns about knee j
      // (2) in the library, from its own screw types, equals the oracle's reciprocal products.
      const LimbPowers P = limbPowers(PlanarWrench::forceThrough(C, (C - B[i]).normalized()),
                                      PlanarTwist::rotationAbout(A[i]), PlanarTwist::rotationAbout(B[j]));
      EXPECT_NEAR(P.input, std::abs(reciprocal(T, in)), 1e-12);
      EXPECT_NEAR(P.output, std::abs(reciprocal(T, out)), 1e-12);
      lambda[i] = std::abs(reciprocal(T, in)) / maxPower(B[i], in);
      eta[i] = std::abs(reciprocal(T, out)) / maxPower(C, out);
    }
    const TransmissionIndices t = transmissionIndices(p);
    EXPECT_NEAR(t.iti_rear, lambda[0], 1e-9);
    EXPECT_NEAR(t.iti_fore, lambda[1], 1e-9);
    EXPECT_NEAR(eta[0], eta[1], 1e-9);  // the OTI is the same for both chains
    EXPECT_NEAR(t.oti, std::min(eta[0], eta[1]), 1e-9);
    EXPECT_NEAR(t.lti(), std::min({lambda[0], lambda[1], eta[0], eta[1]}), 1e-9);
    // Generalized-coordinate form: |sin q5|, |sin q7|, |sin(q6 + q7 - q4 - q5)|.
    EXPECT_NEAR(t.iti_rear, std::abs(std::sin(p.knee_rear)), 1e-12);
    EXPECT_NEAR(t.iti_fore, std::abs(std::sin(p.knee_fore)), 1e-12);
    EXPECT_NEAR(t.oti, std::abs(std::sin(p.q_fore + p.knee_fore - p.q_rear - p.knee_rear)), 1e-12);
    ++checked;
  });
  EXPECT_EQ(checked, 1600);
}

TEST(MftIndices, OtiFromLockingOneHipMatchesTheClosedForm) {
  // Lock the fore hip, drive the rear one: the foot velocity is perpendicular to the fore shank, and the
  // power of the rear transmission force on it, over its maximum, is the OTI.
  const FiveBarGeometry g = kGeometries[1];
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> q(-1.5, 1.5);
  for (int n = 0; n < 200;) {
    FiveBarPose p;
    if (fiveBarForward(g, q(rng), q(rng), &p) != FiveBarStatus::Ok) continue;
    ++n;
    const Eigen::Vector2d v = fiveBarFootJacobian(g, p).col(0);
    if (v.norm() < 1e-9) continue;
    const Eigen::Vector2d f = (p.foot - p.knee_point_rear).normalized();
    EXPECT_NEAR(std::abs(f.dot(v)) / v.norm(), transmissionIndices(p).oti, 1e-9);
    EXPECT_NEAR(transmissionAngleSine(f, v), std::abs(f.dot(v)) / v.norm(), 1e-15);
  }
}

// (1) against the angle between the two vectors taken with atan2: |f.v| / (|f||v|) = |cos(angle_f - angle_v)|.
TEST(MftIndices, TransmissionAngleSineIsTheCosineOfTheAngleBetweenForceAndVelocity) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), length(1e-3, 1e3);
  for (int n = 0; n < 1000; ++n) {
    const double a = angle(rng), b = angle(rng), lf = length(rng), lv = length(rng);
    const Eigen::Vector2d f(lf * std::cos(a), lf * std::sin(a)), v(lv * std::cos(b), lv * std::sin(b));
    const double expected = std::abs(std::cos(std::atan2(f.y(), f.x()) - std::atan2(v.y(), v.x())));
    const double s = transmissionAngleSine(f, v);
    EXPECT_NEAR(s, expected, 1e-12);
    EXPECT_GE(s, 0.0);
    EXPECT_LE(s, 1.0);
    EXPECT_EQ(transmissionAngleSine(-f, v), s);  // the sign of the power does not matter
  }
  // Force along the motion: all the power passes; across it: none; no force or no motion: 0, not NaN.
  EXPECT_DOUBLE_EQ(transmissionAngleSine({3.0, 4.0}, {-0.6, -0.8}), 1.0);
  EXPECT_EQ(transmissionAngleSine({3.0, 4.0}, {-4.0, 3.0}), 0.0);
  EXPECT_EQ(transmissionAngleSine({0.0, 0.0}, {1.0, 2.0}), 0.0);
  EXPECT_EQ(transmissionAngleSine({1.0, 2.0}, {0.0, 0.0}), 0.0);
  EXPECT_NEAR(transmissionAngleSine({1.0, 0.0}, {std::cos(M_PI / 3), std::sin(M_PI / 3)}), 0.5, 1e-15);
}

// The reciprocal product of a pure force f through Q with a rotation of rate w about P is the power f . v_Q,
// v_Q = w perp(Q - P), computed here on the point of application itself, and does not depend on the origin.
TEST(MftIndices, ReciprocalProductIsThePowerAtThePointOfApplication) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int n = 0; n < 500; ++n) {
    const Eigen::Vector2d Q(u(rng), u(rng)), P(u(rng), u(rng)), f(u(rng), u(rng)), shift(u(rng), u(rng));
    const double w = u(rng);
    const Eigen::Vector2d r = Q - P;
    const double power = f.x() * (-w * r.y()) + f.y() * (w * r.x());
    EXPECT_NEAR(reciprocalProduct(PlanarWrench::forceThrough(Q, f), PlanarTwist::rotationAbout(P, w)), power, 1e-12);
    EXPECT_NEAR(reciprocalProduct(PlanarWrench::forceThrough(Q + shift, f), PlanarTwist::rotationAbout(P + shift, w)),
                power, 1e-12);
    // The test's own screw types agree (unit rate).
    EXPECT_NEAR(reciprocalProduct(PlanarWrench::forceThrough(Q, f), PlanarTwist::rotationAbout(P)),
                reciprocal(forceThrough(Q, f), rotationAbout(P)), 1e-12);
    // A translation (w = 0): the power is f . v.
    const PlanarTwist translation{0.0, r};
    EXPECT_NEAR(reciprocalProduct(PlanarWrench::forceThrough(Q, f), translation), f.dot(r), 1e-12);
  }
}

// (2) on the five-bar leg at unit hip rate and unit shank force: P_I = l1 |sin knee_i| (the knee point moves at l1
// perpendicular to the thigh) and P_O = l2 |u_r x u_f| (the foot turns about the other knee at distance l2).
TEST(MftIndices, LimbPowersOfTheFiveBarMatchTheClosedForms) {
  forRandomPoses(29, 200, [](const FiveBarGeometry& g, const FiveBarPose& p) {
    const Eigen::Vector2d A[2] = {g.hipRear(), g.hipFore()};
    const Eigen::Vector2d B[2] = {p.knee_point_rear, p.knee_point_fore};
    const double knee[2] = {p.knee_rear, p.knee_fore};
    const double shank_between = p.q_fore + p.knee_fore - p.q_rear - p.knee_rear;
    for (int i = 0; i < 2; ++i) {
      const LimbPowers P = limbPowers(PlanarWrench::forceThrough(p.foot, (p.foot - B[i]).normalized()),
                                      PlanarTwist::rotationAbout(A[i]), PlanarTwist::rotationAbout(B[1 - i]));
      EXPECT_NEAR(P.input, g.l1 * std::abs(std::sin(knee[i])), 1e-12);
      EXPECT_NEAR(P.output, g.l2 * std::abs(std::sin(shank_between)), 1e-12);
    }
  });
}

TEST(MftIndices, SingularConfigurationsGiveZeroNotNaN) {
  const FiveBarGeometry g = kGeometries[0];
  TransmissionIndices t;
  // Thighs coincide: degenerate loop, output singularity.
  EXPECT_EQ(transmissionIndicesAt(g, 0.3, 0.3, &t), FiveBarStatus::Degenerate);
  EXPECT_EQ(t.lti(), 0.0);
  EXPECT_EQ(t.oti, 0.0);
  // Unreachable and non-finite input: zeros.
  EXPECT_EQ(transmissionIndicesAt(kGeometries[3], -1.5, 1.5, &t), FiveBarStatus::Unreachable);
  EXPECT_EQ(t.lti(), 0.0);
  EXPECT_EQ(transmissionIndicesAt(g, NAN, 0.1, &t), FiveBarStatus::Unreachable);
  EXPECT_EQ(t.lti(), 0.0);
  // Full stretch (knees straight) and full fold: input singularities.
  for (double d : {g.l1 + g.l2, g.l2 - g.l1}) {
    FiveBarPose p;
    ASSERT_EQ(fiveBarInverse(g, {0.0, -d}, &p), FiveBarStatus::Ok);
    t = transmissionIndices(p);
    EXPECT_LT(t.lti(), 1e-6) << d;
    EXPECT_FALSE(std::isnan(t.lti()));
  }
  // Near-singular values from the design notes: d = 0.48 - tiny and thighs 0.01 apart.
  FiveBarPose p;
  ASSERT_EQ(fiveBarForward(g, -0.005, 0.005, &p), FiveBarStatus::Ok);
  EXPECT_NEAR(transmissionIndices(p).oti, 0.0085, 2e-4);
}

TEST(MftIndices, EveryIndexIsFiniteAndInRangeOverTheWholeBox) {
  const FiveBarGeometry g = kGeometries[0];
  for (double qr = -3.2; qr <= 3.2; qr += 0.05) {
    for (double qf = -3.2; qf <= 3.2; qf += 0.05) {
      TransmissionIndices t;
      transmissionIndicesAt(g, qr, qf, &t);
      for (double v : {t.iti_rear, t.iti_fore, t.oti, t.lti()}) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0);
        ASSERT_LE(v, 1.0);
      }
    }
  }
}

// The LTI the WBC's diagnostics and the simulator's fall check take from the generalized coordinates equals the
// LTI of the solved five-bar pose (the closed forms above), for both legs.
TEST(MftIndices, LegIndexFromGeneralizedCoordinatesMatchesTheSolvedPose) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> q(-1.9, 1.9);
  const FiveBarGeometry g = kGeometries[0];
  int checked = 0;
  while (checked < 400) {
    FiveBarPose p;
    if (fiveBarForward(g, q(rng), q(rng), &p) != FiveBarStatus::Ok) continue;
    for (int leg = 0; leg < 2; ++leg) {
      VectorQ gq = VectorQ::Zero();
      gq[hipRearIndex(leg)] = p.q_rear;
      gq[kneeRearIndex(leg)] = p.knee_rear;
      gq[hipForeIndex(leg)] = p.q_fore;
      gq[kneeForeIndex(leg)] = p.knee_fore;
      EXPECT_NEAR(legTransmissionIndex(gq, leg), transmissionIndices(p).lti(), 1e-12);
    }
    ++checked;
  }
}
