// Leg inertia M_a against kinetic energy from finite differences of the kinematics; RACI against the
// massless-link closed form of docs/reference/five-bar-theory.md#acceleration-capacity-raci-and-leg-inertia, and the vertical stance numbers of docs/reference/five-bar-theory.md#vertical-stance-numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "model/mft_criteria.hpp"
#include "model/mft_raci.hpp"

using namespace mft::model;

namespace {
RobotDescription robot() { return loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }

// Kinetic energy of the leg moving with hip rates qd, from positions at q +- h qd (central differences).
double kineticEnergyFd(const FiveBarGeometry& g, const LegInertiaParams& m, double qr, double qf, Eigen::Vector2d qd) {
  const double h = 1e-6;
  FiveBarPose a, b;
  EXPECT_EQ(fiveBarForward(g, qr - h * qd[0], qf - h * qd[1], &a), FiveBarStatus::Ok);
  EXPECT_EQ(fiveBarForward(g, qr + h * qd[0], qf + h * qd[1], &b), FiveBarStatus::Ok);
  auto vel = [&](const Eigen::Vector2d& pa, const Eigen::Vector2d& pb) { return (pb - pa) / (2 * h); };
  double T = 0.0;
  const Eigen::Vector2d Ah[2] = {g.hipRear(), g.hipFore()};
  const double qa[2] = {a.q_rear, a.q_fore}, qb[2] = {b.q_rear, b.q_fore};
  const double sa[2] = {a.shank_rear, a.shank_fore}, sb[2] = {b.shank_rear, b.shank_fore};
  const Eigen::Vector2d ka[2] = {a.knee_point_rear, a.knee_point_fore}, kb[2] = {b.knee_point_rear, b.knee_point_fore};
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d v_thigh = vel(Ah[i] + m.thigh.com_from_joint_m * linkDirection(qa[i]),
                                        Ah[i] + m.thigh.com_from_joint_m * linkDirection(qb[i]));
    const double w_thigh = (qb[i] - qa[i]) / (2 * h);
    const Eigen::Vector2d v_shank = vel(ka[i] + m.shank.com_from_joint_m * linkDirection(sa[i]),
                                        kb[i] + m.shank.com_from_joint_m * linkDirection(sb[i]));
    const double w_shank = wrapAngle(sb[i] - sa[i]) / (2 * h);
    T += 0.5 * (m.thigh.mass_kg * v_thigh.squaredNorm() + m.thigh.inertia_kgm2 * w_thigh * w_thigh);
    T += 0.5 * (m.shank.mass_kg * v_shank.squaredNorm() + m.shank.inertia_kgm2 * w_shank * w_shank);
  }
  T += 0.5 * m.foot_mass_kg * vel(a.foot, b.foot).squaredNorm();
  return T;
}
}  // namespace

TEST(MftLegInertia, MatchesKineticEnergyFromFiniteDifferences) {
  const RobotDescription d = robot();
  LegInertiaParams m = LegInertiaParams::from(d);
  m.foot_mass_kg = 0.3;
  for (const FiveBarGeometry& g : {FiveBarGeometry::from(d), FiveBarGeometry{0.06, 0.22, 0.26}}) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> qr(-1.9, 0.35), qf(-0.35, 1.9), rate(-3, 3);
    for (int n = 0; n < 300;) {
      FiveBarPose p;
      const double a = qr(rng), b = qf(rng);
      if (b - a < 0.3 || fiveBarForward(g, a, b, &p) != FiveBarStatus::Ok) continue;
      if (std::abs(std::sin(p.knee_rear)) < 0.1 || std::abs(std::sin(p.knee_fore)) < 0.1) continue;
      ++n;
      const Eigen::Vector2d qd(rate(rng), rate(rng));
      const Eigen::Matrix2d M = legActuatedInertia(g, m, p);
      const double T = 0.5 * qd.dot(M * qd);
      EXPECT_NEAR(T, kineticEnergyFd(g, m, a, b, qd), 1e-6 * std::max(1.0, T));
      EXPECT_GT(M.determinant(), 0.0);
    }
  }
}

TEST(MftRaci, MasslessLinksWithFootMassMatchTheClosedForm) {
  // M_a = m J'J, so tau~_i* = a_max sqrt(2 m (1 + eta) / eta) for both actuators.
  LegInertiaParams m;
  m.thigh = {0.22, 1e-12, 0.1, 1e-14};
  m.shank = {0.26, 1e-12, 0.1, 1e-14};
  m.foot_mass_kg = 1.7;
  RaciOptions o;
  o.accel_max_mps2 = 60.0;
  for (const FiveBarGeometry& g : {FiveBarGeometry{0.0, 0.22, 0.26}, FiveBarGeometry{0.06, 0.22, 0.26}}) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> q(-1.9, 1.9);
    for (int n = 0; n < 300;) {
      FiveBarPose p;
      if (fiveBarForward(g, q(rng), q(rng), &p) != FiveBarStatus::Ok) continue;
      const TransmissionIndices t = transmissionIndices(p);
      if (t.lti() < 0.05) continue;
      ++n;
      const double expect = o.accel_max_mps2 * std::sqrt(2.0 * m.foot_mass_kg * (1.0 + t.oti) / t.oti);
      const RaciResult r = computeRaci(g, m, p, o);
      EXPECT_NEAR(r.tau_rear, expect, 1e-6 * expect);
      EXPECT_NEAR(r.tau_fore, expect, 1e-6 * expect);
    }
  }
}

TEST(MftRaci, OptimalRatioIsALowerBoundOfEveryFixedDrive) {
  const RobotDescription d = robot();
  const FiveBarGeometry g = FiveBarGeometry::from(d);
  const LegInertiaParams m = LegInertiaParams::from(d);
  FiveBarPose p;
  ASSERT_EQ(fiveBarInverse(g, {0.05, -0.35}, &p), FiveBarStatus::Ok);
  RaciOptions o = RaciOptions::fromRobot(d);
  const double opt = computeRaci(g, m, p, o).raci;
  o.form = RaciForm::FixedDrive;
  for (double k : {0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 3.0}) {
    o.drive_k = k;
    EXPECT_LE(opt, computeRaci(g, m, p, o).raci + 1e-9) << k;
  }
}

TEST(MftRaci, ActuatorNumbersComeFromTheRobotDescription) {
  const RobotDescription d = robot();
  EXPECT_NEAR(actuatorRaciLimit(d.actuator), 174.54, 1e-9);
  EXPECT_NEAR(RaciOptions::fromRobot(d).drive_k, 0.3, 1e-12);
  const MftCriteria c = MftCriteria::defaults(d);
  EXPECT_NEAR(c.raci.hi, 174.54, 1e-9);
  EXPECT_EQ(c.lti.lo, 0.7);
  EXPECT_EQ(c.raci_options.form, RaciForm::OptimalRatio);
}

TEST(MftRaci, SingularConfigurationsAreInfiniteNotNaN) {
  const RobotDescription d = robot();
  const MftLegModel leg = MftLegModel::from(d);
  const MftCriteria c = MftCriteria::defaults(d);
  for (const auto& q : {Eigen::Vector2d(0.2, 0.2), Eigen::Vector2d(NAN, 0.0)}) {
    const LegEvaluation e = evaluateLegAt(leg, c, q.x(), q.y());
    EXPECT_FALSE(std::isnan(e.raci.raci));
    EXPECT_TRUE(std::isinf(e.raci.raci));
    EXPECT_EQ(e.indices.lti(), 0.0);
    EXPECT_FALSE(e.preferable);
  }
  FiveBarPose p;
  ASSERT_EQ(fiveBarInverse(leg.geometry, {0.0, -(leg.geometry.l1 + leg.geometry.l2)}, &p), FiveBarStatus::Ok);
  const RaciResult r = computeRaci(leg.geometry, leg.inertia, p, c.raci_options);
  EXPECT_TRUE(r.singular);
  EXPECT_TRUE(std::isinf(r.raci));
}

TEST(MftRaci, VerticalStanceTableOfTheDesignNotes) {
  // docs/reference/five-bar-theory.md#vertical-stance-numbers: z_B, ITI, OTI, LTI, RACI* (optimal), RACI (k = 0.3), RACI* with gravity.
  struct Row {
    double z, iti, oti, lti, opt, fixed, grav;
  };
  const Row rows[] = {{0.38, 0.969, 0.929, 0.929, 154.5, 155.0, 163.3}, {0.40, 0.923, 0.875, 0.875, 158.2, 159.0, 166.4},
                      {0.42, 0.849, 0.797, 0.797, 165.0, 166.6, 172.5}, {0.43, 0.798, 0.746, 0.746, 170.4, 172.8, 177.5},
                      {0.435, 0.768, 0.716, 0.716, 174.0, 176.8, 180.8}, {0.44, 0.735, 0.683, 0.683, 178.3, 181.9, 184.9},
                      {0.46, 0.549, 0.507, 0.507, 212.6, 223.1, 217.9}};
  const RobotDescription d = robot();
  const MftLegModel leg = MftLegModel::from(d);
  MftCriteria opt = MftCriteria::defaults(d), fixed = opt, grav = opt;
  fixed.raci_options.form = RaciForm::FixedDrive;
  grav.raci_options.gravity = true;
  for (const Row& r : rows) {
    const LegEvaluation e = evaluateVerticalStance(leg, opt, r.z);
    ASSERT_EQ(e.status, FiveBarStatus::Ok);
    EXPECT_NEAR(e.indices.iti(), r.iti, 6e-4) << r.z;
    EXPECT_NEAR(e.indices.oti, r.oti, 6e-4) << r.z;
    EXPECT_NEAR(e.indices.lti(), r.lti, 6e-4) << r.z;
    EXPECT_NEAR(e.raci.raci, r.opt, 0.06) << r.z;
    EXPECT_NEAR(evaluateVerticalStance(leg, fixed, r.z).raci.raci, r.fixed, 0.06) << r.z;
    EXPECT_NEAR(evaluateVerticalStance(leg, grav, r.z).raci.raci, r.grav, 0.06) << r.z;
    // Preferable by the indices exactly below the band edge d ~ 0.4356.
    EXPECT_EQ(e.preferable, r.z < 0.4356) << r.z;
  }
}
