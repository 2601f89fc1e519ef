// Planar floating-base dynamics (model/planar_dynamics.hpp): kinematics and Jacobians against finite
// differences, the mass matrix and the RNEA bias against an independent Lagrangian computation, the closed-loop
// forward dynamics of paper eq. 1, the inverse dynamics of eq. 7, a passive energy-conserving integration, the
// closed-loop configuration helper, and that updateModel does not allocate.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/five_bar.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"

using namespace mft::model;

// ---- heap-allocation counter (glibc): every malloc of the process passes through here --------------------
// Sanitizers bring their own allocator, so the counter is compiled out under them and the test skips.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || defined(__SANITIZE_MEMORY__)
#define MFT_NO_MALLOC_HOOK 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define MFT_NO_MALLOC_HOOK 1
#endif
#endif

namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
}  // namespace

#if !defined(MFT_NO_MALLOC_HOOK) && defined(__GLIBC__)
#define MFT_HAVE_MALLOC_HOOK 1
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* malloc(std::size_t size) {
  if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
void free(void* p) { __libc_free(p); }
}
#endif

namespace {

using PointJacobian = Eigen::Matrix<double, 2, kNq>;

const RobotDescription& robot() {
  static const RobotDescription d = loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  return d;
}

// The project robot and a variant with separated hips (exercises the hip offsets, which are zero on the robot).
std::vector<RobotDescription> descriptions() {
  RobotDescription spaced = robot();
  spaced.hip_spacing_m = 0.06;
  return {robot(), spaced};
}

double uniform(std::mt19937& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

// A random configuration with both loops closed, feet away from the workspace boundary, and a velocity that
// satisfies the closure (the least-squares projection of a random velocity onto the null space of J_h).
void randomClosedState(std::mt19937& rng, const RobotDescription& d, const PlanarModel& model, VectorQ* q,
                       VectorQ* qd) {
  const Eigen::Vector3d base(uniform(rng, -0.5, 0.5), uniform(rng, 0.3, 0.6), uniform(rng, -0.4, 0.4));
  Eigen::Vector2d feet[2];
  for (auto& foot : feet) {
    const double reach = uniform(rng, 0.24, 0.43), angle = uniform(rng, -0.5, 0.5);
    foot = reach * linkDirection(angle);
  }
  *q = closedLoopConfiguration(d, base, feet[0], feet[1]);
  VectorQ raw;
  for (int i = 0; i < kNq; ++i) raw(i) = uniform(rng, -2.0, 2.0);
  ModelData data;
  updateModel(model, *q, VectorQ::Zero(), &data);
  const Eigen::Matrix<double, kNh, kNh> JJt = data.Jh * data.Jh.transpose();
  *qd = raw - data.Jh.transpose() * JJt.llt().solve(data.Jh * raw);
}

// A configuration with no closure at all (every coordinate anywhere) and any velocity.
void randomOpenState(std::mt19937& rng, VectorQ* q, VectorQ* qd) {
  for (int i = 0; i < kNq; ++i) {
    (*q)(i) = i < 2 ? uniform(rng, -1.0, 1.0) : uniform(rng, -M_PI, M_PI);
    (*qd)(i) = uniform(rng, -3.0, 3.0);
  }
}

// Central finite-difference Jacobian of a vector function of q.
template <int Rows, class F>
Eigen::Matrix<double, Rows, kNq> finiteDifferenceJacobian(F&& f, const VectorQ& q, double step = 1e-6) {
  Eigen::Matrix<double, Rows, kNq> J;
  for (int i = 0; i < kNq; ++i) {
    VectorQ qp = q, qm = q;
    qp(i) += step;
    qm(i) -= step;
    J.col(i) = (f(qp) - f(qm)) / (2.0 * step);
  }
  return J;
}

// Central finite difference of J(q) qd along qd: d/dt (J) qd = Jdot qd.
template <int Rows, class F>
Eigen::Matrix<double, Rows, 1> finiteDifferenceJdotQd(F&& jacobian, const VectorQ& q, const VectorQ& qd,
                                                      double step = 1e-6) {
  const Eigen::Matrix<double, Rows, kNq> Jp = jacobian(VectorQ(q + step * qd));
  const Eigen::Matrix<double, Rows, kNq> Jm = jacobian(VectorQ(q - step * qd));
  return (Jp - Jm) * qd / (2.0 * step);
}

ModelData updated(const PlanarModel& model, const VectorQ& q, const VectorQ& qd) {
  ModelData data;
  updateModel(model, q, qd, &data);
  return data;
}

// Both sample sets the Jacobian tests run on: closed-loop states of both geometries and arbitrary states.
struct Sample {
  PlanarModel model;
  VectorQ q, qd;
  std::string label;
};
std::vector<Sample> samples(int per_set, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Sample> out;
  for (const RobotDescription& d : descriptions()) {
    const PlanarModel model = buildBipedModel(d);
    for (int k = 0; k < per_set; ++k) {
      Sample s{model, VectorQ::Zero(), VectorQ::Zero(), "closed s=" + std::to_string(d.hip_spacing_m) + " #" + std::to_string(k)};
      randomClosedState(rng, d, model, &s.q, &s.qd);
      out.push_back(s);
      Sample o{model, VectorQ::Zero(), VectorQ::Zero(), "open s=" + std::to_string(d.hip_spacing_m) + " #" + std::to_string(k)};
      randomOpenState(rng, &o.q, &o.qd);
      out.push_back(o);
    }
  }
  return out;
}

// Christoffel-symbol Coriolis matrix from finite differences of M: C_ij = sum_k c_ijk qd_k.
MatrixQ christoffelCoriolis(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, double step = 1e-6) {
  std::array<MatrixQ, kNq> dM;  // dM[k] = dM/dq_k
  ModelData data;
  for (int k = 0; k < kNq; ++k) {
    VectorQ qp = q, qm = q;
    qp(k) += step;
    qm(k) -= step;
    massMatrix(model, qp, &data);
    const MatrixQ Mp = data.M;
    massMatrix(model, qm, &data);
    dM[k] = (Mp - data.M) / (2.0 * step);
  }
  MatrixQ C = MatrixQ::Zero();
  for (int i = 0; i < kNq; ++i)
    for (int j = 0; j < kNq; ++j)
      for (int k = 0; k < kNq; ++k) C(i, j) += 0.5 * (dM[k](i, j) + dM[j](i, k) - dM[i](j, k)) * qd(k);
  return C;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Closed-loop configurations
// ---------------------------------------------------------------------------------------------------------

TEST(DynamicsConfiguration, NominalStanceMatchesTheDesignNotes) {
  const VectorQ q = closedLoopConfiguration(robot(), {0.0, 0.40, 0.0}, {0.0, -0.40}, {0.0, -0.40});
  for (int leg = 0; leg < kNumLegs; ++leg) {
    EXPECT_NEAR(q(hipRearIndex(leg)), -0.6435, 1e-4);
    EXPECT_NEAR(q(kneeRearIndex(leg)), 1.176, 1e-3);
    EXPECT_NEAR(q(hipForeIndex(leg)), 0.6435, 1e-4);
    EXPECT_NEAR(q(kneeForeIndex(leg)), -1.176, 1e-3);
  }
  EXPECT_EQ(q(kBaseX), 0.0);
  EXPECT_EQ(q(kBaseZ), 0.40);
  EXPECT_EQ(q(kBasePitch), 0.0);
  // Base 0.40 m above the ground, feet straight below: both feet on the ground at x = 0.
  const ModelData data = updated(buildBipedModel(robot()), q, VectorQ::Zero());
  EXPECT_LT(data.foot_pos.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(DynamicsConfiguration, LoopsCloseAndFeetLandWhereAsked) {
  std::mt19937 rng(21);
  for (const RobotDescription& d : descriptions()) {
    const PlanarModel model = buildBipedModel(d);
    for (int k = 0; k < 500; ++k) {
      const Eigen::Vector3d base(uniform(rng, -2, 2), uniform(rng, -1, 1), uniform(rng, -M_PI, M_PI));
      const Eigen::Vector2d right = uniform(rng, 0.1, 0.44) * linkDirection(uniform(rng, -1.2, 1.2));
      const Eigen::Vector2d left = uniform(rng, 0.1, 0.44) * linkDirection(uniform(rng, -1.2, 1.2));
      const VectorQ q = closedLoopConfiguration(d, base, right, left);
      const ModelData data = updated(model, q, VectorQ::Zero());
      EXPECT_LT(data.closure_error.cwiseAbs().maxCoeff(), 1e-12);
      // The foot (rear shank tip) is the requested point of the base frame, seen in the world.
      const Eigen::Rotation2Dd R(base.z());
      EXPECT_LT((data.foot_pos.head<2>() - (base.head<2>() + R * right)).norm(), 1e-12);
      EXPECT_LT((data.foot_pos.tail<2>() - (base.head<2>() + R * left)).norm(), 1e-12);
      // Assembly mode of five_bar.hpp: rear knee bends backward, fore knee forward.
      for (int leg = 0; leg < kNumLegs; ++leg) {
        EXPECT_GT(q(kneeRearIndex(leg)), 0.0);
        EXPECT_LT(q(kneeForeIndex(leg)), 0.0);
      }
    }
  }
}

TEST(DynamicsConfiguration, BadInputThrows) {
  const Eigen::Vector3d base(0.0, 0.4, 0.0);
  const Eigen::Vector2d ok(0.0, -0.40);
  EXPECT_THROW(closedLoopConfiguration(robot(), base, {0.0, -0.49}, ok), std::invalid_argument);  // beyond l1 + l2
  EXPECT_THROW(closedLoopConfiguration(robot(), base, ok, {0.0, -0.03}), std::invalid_argument);  // inside |l2 - l1|
  EXPECT_THROW(closedLoopConfiguration(robot(), base, ok, {0.6, 0.0}), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(closedLoopConfiguration(robot(), base, {nan, -0.4}, ok), std::invalid_argument);
  EXPECT_THROW(closedLoopConfiguration(robot(), {0.0, nan, 0.0}, ok, ok), std::invalid_argument);
  EXPECT_NO_THROW(closedLoopConfiguration(robot(), base, ok, ok));

  const PlanarModel model = buildBipedModel(robot());
  const VectorQ q = VectorQ::Zero();
  EXPECT_THROW(pointPosition(model, q, kNq, {0, 0}), std::invalid_argument);
  EXPECT_THROW(bodyPose(model, q, -1), std::invalid_argument);
  PlanarModel truncated = model;
  truncated.bodies.pop_back();
  ModelData data;
  EXPECT_THROW(updateModel(truncated, q, q, &data), std::invalid_argument);
  PlanarModel cyclic = model;
  cyclic.bodies[3].parent = 5;  // a parent after its child: not a topologically ordered tree
  EXPECT_THROW(updateModel(cyclic, q, q, &data), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------------
// Kinematics
// ---------------------------------------------------------------------------------------------------------

TEST(DynamicsKinematics, BodyFramesFollowTheConventions) {
  const PlanarModel model = buildBipedModel(robot());
  const double l1 = robot().thigh.length_m, l2 = robot().shank.length_m;
  VectorQ q = VectorQ::Zero();
  q << 0.3, 0.5, 0.2, -0.4, 1.1, 0.5, -0.9, 0.1, 0.2, 0.3, -0.4;
  const Eigen::Vector2d base(q(kBaseX), q(kBaseZ));
  for (int leg = 0; leg < kNumLegs; ++leg) {
    // A link at absolute CCW angle a points along (sin a, -cos a); knee angles are relative.
    const double thigh = q(kBasePitch) + q(hipRearIndex(leg));
    const double shank = thigh + q(kneeRearIndex(leg));
    const Eigen::Vector2d knee = base + l1 * linkDirection(thigh);
    const Eigen::Vector2d tip = knee + l2 * linkDirection(shank);
    const Eigen::Vector3d knee_pose = bodyPose(model, q, kneeRearIndex(leg));
    EXPECT_LT((knee_pose.head<2>() - knee).norm(), 1e-14);
    EXPECT_NEAR(knee_pose.z(), shank, 1e-14);
    EXPECT_LT((pointPosition(model, q, model.rearShankBody(leg), model.shankTip()) - tip).norm(), 1e-14);
  }
  // The torso CoM sits at torso_com in the pitched base frame.
  const Eigen::Vector2d torso_com(robot().torso_com_m[0], robot().torso_com_m[1]);
  EXPECT_LT((pointPosition(model, q, kBasePitch, torso_com) - (base + Eigen::Rotation2Dd(q(kBasePitch)) * torso_com)).norm(),
            1e-14);
}

TEST(DynamicsKinematics, CentreOfMassIsTheMassWeightedAverage) {
  const RobotDescription& d = robot();
  const PlanarModel model = buildBipedModel(d);
  // Legs hanging straight down, level torso: the CoM height follows from the description by hand.
  const VectorQ q = (VectorQ() << 0.1, 0.5, 0.0, 0, 0, 0, 0, 0, 0, 0, 0).finished();
  const ModelData data = updated(model, q, VectorQ::Zero());
  const double leg_moment = 2.0 * (-d.thigh.mass_kg * d.thigh.com_from_joint_m -
                                   d.shank.mass_kg * (d.thigh.length_m + d.shank.com_from_joint_m));
  const double com_z = 0.5 + (d.torso_mass_kg * d.torso_com_m[1] + 2.0 * leg_moment) / d.totalMass();
  EXPECT_NEAR(data.total_mass, d.totalMass(), 1e-12);
  EXPECT_NEAR(data.com.x(), 0.1 + d.torso_mass_kg * d.torso_com_m[0] / d.totalMass(), 1e-12);
  EXPECT_NEAR(data.com.y(), com_z, 1e-12);
  EXPECT_NEAR(potentialEnergy(model, q), d.totalMass() * d.gravity_mps2 * com_z, 1e-9);
}

TEST(DynamicsKinematics, JacobiansMatchFiniteDifferences) {
  std::mt19937 rng(7);
  for (const Sample& s : samples(40, 3)) {
    SCOPED_TRACE(s.label);
    const ModelData data = updated(s.model, s.q, s.qd);
    const auto feet = [&](const VectorQ& x) { return VectorC(updated(s.model, x, s.qd).foot_pos); };
    const auto closure = [&](const VectorQ& x) { return VectorH(updated(s.model, x, s.qd).closure_error); };
    const auto com = [&](const VectorQ& x) { return Eigen::Vector2d(updated(s.model, x, s.qd).com); };
    const double tol = 1e-8;
    EXPECT_LT((data.Jc - finiteDifferenceJacobian<kNc>(feet, s.q)).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((data.Jh - finiteDifferenceJacobian<kNh>(closure, s.q)).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((data.Jcom - finiteDifferenceJacobian<2>(com, s.q)).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((data.foot_vel - data.Jc * s.qd).norm(), 1e-12);
    EXPECT_LT((data.com_vel - data.Jcom * s.qd).norm(), 1e-12);

    // Any point of any body through the free functions.
    const int body = std::uniform_int_distribution<int>(0, kNq - 1)(rng);
    const Eigen::Vector2d point(uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3));
    PointJacobian J;
    pointJacobian(s.model, s.q, body, point, &J);
    const auto position = [&](const VectorQ& x) { return pointPosition(s.model, x, body, point); };
    EXPECT_LT((J - finiteDifferenceJacobian<2>(position, s.q)).cwiseAbs().maxCoeff(), tol);
    // The angle of a body frame is the sum of the revolute coordinates on its path.
    const auto angle = [&](const VectorQ& x) { return Eigen::Matrix<double, 1, 1>(bodyPose(s.model, x, body).z()); };
    const Eigen::Matrix<double, 1, kNq> J_angle = finiteDifferenceJacobian<1>(angle, s.q);
    for (int j = 0; j < kNq; ++j) EXPECT_TRUE(std::abs(J_angle(j)) < 1e-9 || std::abs(J_angle(j) - 1.0) < 1e-9);
  }
}

TEST(DynamicsKinematics, JdotQdMatchesFiniteDifferences) {
  std::mt19937 rng(8);
  for (const Sample& s : samples(40, 4)) {
    SCOPED_TRACE(s.label);
    const ModelData data = updated(s.model, s.q, s.qd);
    const auto Jc = [&](const VectorQ& x) { return MatrixCQ(updated(s.model, x, s.qd).Jc); };
    const auto Jh = [&](const VectorQ& x) { return MatrixHQ(updated(s.model, x, s.qd).Jh); };
    const auto Jcom = [&](const VectorQ& x) { return PointJacobian(updated(s.model, x, s.qd).Jcom); };
    const double tol = 1e-7 * (1.0 + s.qd.squaredNorm());
    EXPECT_LT((data.Jc_dot_qd - finiteDifferenceJdotQd<kNc>(Jc, s.q, s.qd)).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((data.Jh_dot_qd - finiteDifferenceJdotQd<kNh>(Jh, s.q, s.qd)).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((data.Jcom_dot_qd - finiteDifferenceJdotQd<2>(Jcom, s.q, s.qd)).cwiseAbs().maxCoeff(), tol);

    const int body = std::uniform_int_distribution<int>(0, kNq - 1)(rng);
    const Eigen::Vector2d point(uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3));
    const auto J = [&](const VectorQ& x) {
      PointJacobian out;
      pointJacobian(s.model, x, body, point, &out);
      return out;
    };
    EXPECT_LT((pointJdotQd(s.model, s.q, s.qd, body, point) - finiteDifferenceJdotQd<2>(J, s.q, s.qd)).cwiseAbs().maxCoeff(),
              tol);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Mass matrix, bias forces, energies
// ---------------------------------------------------------------------------------------------------------

TEST(DynamicsInertia, MassMatrixIsSymmetricPositiveDefiniteAndMatchesBodyEnergies) {
  for (const Sample& s : samples(30, 5)) {
    SCOPED_TRACE(s.label);
    const ModelData data = updated(s.model, s.q, s.qd);
    const MatrixQ& M = data.M;
    EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff());
    const Eigen::SelfAdjointEigenSolver<MatrixQ> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 1e-6);

    // Independent M: sum over bodies of m Jv'Jv + I Jw'Jw, with Jv the CoM Jacobian and Jw the angle gradient.
    MatrixQ M_bodies = MatrixQ::Zero();
    for (int i = 0; i < kNq; ++i) {
      const PlanarBody& b = s.model.bodies[i];
      PointJacobian Jv;
      pointJacobian(s.model, s.q, i, b.com, &Jv);
      const auto angle = [&](const VectorQ& x) { return Eigen::Matrix<double, 1, 1>(bodyPose(s.model, x, i).z()); };
      const Eigen::Matrix<double, 1, kNq> Jw = finiteDifferenceJacobian<1>(angle, s.q);
      M_bodies += b.mass * Jv.transpose() * Jv + b.inertia * Jw.transpose() * Jw;
    }
    EXPECT_LT((M - M_bodies).cwiseAbs().maxCoeff(), 1e-8);
    // The free function gives the same matrix.
    ModelData alone;
    massMatrix(s.model, s.q, &alone);
    EXPECT_LT((alone.M - M).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(kineticEnergy(data, s.qd), 0.5 * s.qd.dot(M_bodies * s.qd), 1e-8 * (1.0 + kineticEnergy(data, s.qd)));
  }
}

TEST(DynamicsInertia, BiasForcesMatchTheLagrangianDerivatives) {
  // h = Mdot qd - dT/dq + dV/dq, every term by central finite differences of M, T and V.
  for (const Sample& s : samples(30, 6)) {
    SCOPED_TRACE(s.label);
    const ModelData data = updated(s.model, s.q, s.qd);
    const double step = 1e-5;
    ModelData tmp;
    massMatrix(s.model, s.q + step * s.qd, &tmp);
    const MatrixQ Mp = tmp.M;
    massMatrix(s.model, s.q - step * s.qd, &tmp);
    const MatrixQ Mdot = (Mp - tmp.M) / (2.0 * step);
    const auto kinetic = [&](const VectorQ& x) {
      massMatrix(s.model, x, &tmp);
      return Eigen::Matrix<double, 1, 1>(kineticEnergy(tmp, s.qd));
    };
    const auto potential = [&](const VectorQ& x) { return Eigen::Matrix<double, 1, 1>(potentialEnergy(s.model, x)); };
    const VectorQ dT_dq = finiteDifferenceJacobian<1>(kinetic, s.q, step).transpose();
    const VectorQ dV_dq = finiteDifferenceJacobian<1>(potential, s.q, step).transpose();
    const VectorQ h_lagrange = Mdot * s.qd - dT_dq + dV_dq;
    EXPECT_LT((data.h - h_lagrange).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + data.h.cwiseAbs().maxCoeff()));

    // The gravity part alone (qd = 0) is the gradient of the potential energy.
    ModelData at_rest;
    biasForces(s.model, s.q, VectorQ::Zero(), &at_rest);
    EXPECT_LT((at_rest.h - dV_dq).cwiseAbs().maxCoeff(), 1e-7);
    // The free function gives the same bias as updateModel.
    ModelData alone;
    biasForces(s.model, s.q, s.qd, &alone);
    EXPECT_LT((alone.h - data.h).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(DynamicsInertia, MdotMinusTwoCIsSkewSymmetric) {
  // With C the Christoffel matrix of M (finite differences): C qd is the velocity part of the RNEA bias, and
  // Mdot - 2C is skew, hence qd'(Mdot qd - 2 (h - g)) = 0: Coriolis forces do no work (dT/dt = qd'(tau - g)).
  for (const Sample& s : samples(10, 9)) {
    SCOPED_TRACE(s.label);
    const ModelData data = updated(s.model, s.q, s.qd);
    ModelData at_rest;
    biasForces(s.model, s.q, VectorQ::Zero(), &at_rest);
    const VectorQ velocity_bias = data.h - at_rest.h;
    const MatrixQ C = christoffelCoriolis(s.model, s.q, s.qd);
    const double step = 1e-6;
    ModelData tmp;
    massMatrix(s.model, s.q + step * s.qd, &tmp);
    const MatrixQ Mp = tmp.M;
    massMatrix(s.model, s.q - step * s.qd, &tmp);
    const MatrixQ Mdot = (Mp - tmp.M) / (2.0 * step);
    const double scale = 1.0 + velocity_bias.cwiseAbs().maxCoeff();
    EXPECT_LT((C * s.qd - velocity_bias).cwiseAbs().maxCoeff(), 1e-6 * scale);
    const MatrixQ skew = Mdot - 2.0 * C;
    EXPECT_LT((skew + skew.transpose()).cwiseAbs().maxCoeff(), 1e-6 * scale);
    EXPECT_LT(std::abs(s.qd.dot(Mdot * s.qd - 2.0 * velocity_bias)), 1e-6 * scale * (1.0 + s.qd.squaredNorm()));
  }
}

// ---------------------------------------------------------------------------------------------------------
// Constrained dynamics (paper eq. 1-7)
// ---------------------------------------------------------------------------------------------------------

namespace {
// A random closed-loop state with random joint torques and contact forces.
struct LoadedState {
  VectorQ q, qd;
  VectorA tau;
  VectorC f_c;
};

// Calls check(k, state, model data) for `per_robot` random loaded states of every robot description.
template <class Check>
void forRandomLoadedStates(std::mt19937& rng, int per_robot, Check&& check) {
  for (const RobotDescription& d : descriptions()) {
    const PlanarModel model = buildBipedModel(d);
    for (int k = 0; k < per_robot; ++k) {
      LoadedState s;
      randomClosedState(rng, d, model, &s.q, &s.qd);
      for (int i = 0; i < kNa; ++i) s.tau(i) = uniform(rng, -40.0, 40.0);
      s.f_c << uniform(rng, -80.0, 80.0), uniform(rng, 0.0, 250.0), uniform(rng, -80.0, 80.0), uniform(rng, 0.0, 250.0);
      check(k, s, updated(model, s.q, s.qd));
    }
  }
}
}  // namespace

TEST(DynamicsConstrained, ForwardDynamicsKeepsTheLoopsClosed) {
  std::mt19937 rng(11);
  forRandomLoadedStates(rng, 200, [](int, const LoadedState& s, const ModelData& data) {
    const VectorQ& qd = s.qd;
    const VectorA& tau = s.tau;
    const VectorC& f_c = s.f_c;
    VectorQ qdd;
    VectorH f_h;
    constrainedForwardDynamics(data, tau, f_c, &qdd, &f_h);
    EXPECT_LT((data.Jh * qdd + data.Jh_dot_qd).cwiseAbs().maxCoeff(), 1e-10);
    // The first block row of eq. 1 holds too.
    const VectorQ residual = data.M * qdd - data.Jh.transpose() * f_h -
                             (actuationSelector().transpose() * tau + data.Jc.transpose() * f_c - data.h);
    EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-9);
    // Closure forces do no work on closure-consistent motion.
    EXPECT_LT(std::abs(qd.dot(data.Jh.transpose() * f_h)), 1e-9 * (1.0 + f_h.norm()));
  });
}

TEST(DynamicsConstrained, ClosureProjectionProperties) {
  std::mt19937 rng(12);
  const PlanarModel model = buildBipedModel(robot());
  for (int k = 0; k < 100; ++k) {
    VectorQ q, qd;
    randomClosedState(rng, robot(), model, &q, &qd);
    const ModelData data = updated(model, q, qd);
    ClosureProjection proj;
    closureProjection(data, &proj);
    EXPECT_LT((proj.Minv * data.M - MatrixQ::Identity()).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((proj.Lambda_h * (data.Jh * proj.Minv * data.Jh.transpose()) - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(),
              1e-9);
    EXPECT_LT((data.Jh * proj.N_h).cwiseAbs().maxCoeff(), 1e-9);                  // projects onto the closure
    EXPECT_LT((proj.N_h * proj.N_h - proj.N_h).cwiseAbs().maxCoeff(), 1e-9);      // idempotent
    EXPECT_LT((proj.N_h * proj.Minv - (proj.N_h * proj.Minv).transpose()).cwiseAbs().maxCoeff(), 1e-9);  // M-orthogonal
  }
}

TEST(DynamicsConstrained, InverseDynamicsRecoversTheTorquesOfForwardDynamics) {
  // qdd from eq. 1 with known tau and f_c is consistent with the closure and the floating-base rows, so eq. 7
  // must give tau back; eq. 2 and eq. 3 must hold on it as well.
  std::mt19937 rng(13);
  const MatrixAQ Sa = actuationSelector();
  forRandomLoadedStates(rng, 200, [&Sa](int k, LoadedState& s, const ModelData& data) {
    const VectorQ& qd = s.qd;
    const VectorA& tau = s.tau;
    VectorC& f_c = s.f_c;
    if (k % 4 == 0) f_c.setZero();  // flight phase
    VectorQ qdd;
    constrainedForwardDynamics(data, tau, f_c, &qdd, nullptr);
    ClosureProjection proj;
    closureProjection(data, &proj);
    const VectorA tau_back = inverseDynamicsActuated(data, proj, qdd, qd, f_c);
    EXPECT_LT((tau_back - tau).cwiseAbs().maxCoeff(), 1e-7) << "tau " << tau.transpose() << "\nback " << tau_back.transpose();

    const MatrixQ NhT = proj.N_h.transpose();
    const VectorQ eq2 = data.M * qdd + NhT * data.h + data.Jh.transpose() * proj.Lambda_h * data.Jh_dot_qd -
                        NhT * Sa.transpose() * tau - NhT * data.Jc.transpose() * f_c;
    EXPECT_LT(eq2.cwiseAbs().maxCoeff(), 1e-8);
    const Eigen::Vector3d eq3 = (data.M * qdd + NhT * data.h - NhT * data.Jc.transpose() * f_c).head<3>();
    EXPECT_LT(eq3.cwiseAbs().maxCoeff(), 1e-8);
  });
}

// Paper (7) as projectedDynamicsRows gives it, for all 11 rows and for the S_f / S_a selections (8), (9) use:
// the rows equal N_h' built here from a pivoted-LU inverse of M and of J_h M^-1 J_h' (not closureProjection's
// Cholesky), and (7) holds on the qdd and f_h-free solution of the Schur-complement forward dynamics (6).
TEST(DynamicsConstrained, ProjectedDynamicsRowsAreEquationSevenOnForwardDynamicsSolutions) {
  std::mt19937 rng(31);
  const MatrixAQ Sa = actuationSelector();
  constexpr std::array<int, kNq> kAll = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  forRandomLoadedStates(rng, 100, [&Sa, &kAll](int k, LoadedState& s, const ModelData& data) {
    if (k % 4 == 0) s.f_c.setZero();  // flight phase
    VectorQ qdd;
    constrainedForwardDynamics(data, s.tau, s.f_c, &qdd, nullptr);
    ClosureProjection proj;
    closureProjection(data, &proj);
    ProjectedDynamicsRows<kNq> all;
    projectedDynamicsRows<kNq>(data, proj, kAll, &all);

    const MatrixQ Minv = data.M.partialPivLu().inverse();
    const Eigen::Matrix<double, kNh, kNh> Lambda = (data.Jh * Minv * data.Jh.transpose()).partialPivLu().inverse();
    const MatrixQ NhT = MatrixQ::Identity() - data.Jh.transpose() * Lambda * data.Jh * Minv;
    EXPECT_LT((all.NhT - NhT).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_EQ(all.M, data.M);
    EXPECT_EQ(all.JhT, data.Jh.transpose());

    const VectorQ residual = all.M * qdd + all.NhT * data.h + all.JhT * (Lambda * data.Jh_dot_qd) -
                             all.NhT * Sa.transpose() * s.tau - all.NhT * data.Jc.transpose() * s.f_c;
    const double scale = 1.0 + (data.M * qdd).cwiseAbs().maxCoeff() + data.h.cwiseAbs().maxCoeff();
    EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-10 * scale) << residual.transpose();

    // The selections are the same rows.
    ProjectedDynamicsRows<3> base;
    projectedDynamicsRows<3>(data, proj, kBaseIndex, &base);
    ProjectedDynamicsRows<kNa> actuated;
    projectedDynamicsRows<kNa>(data, proj, kActuatedIndex, &actuated);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(base.NhT.row(i), all.NhT.row(kBaseIndex[i]));
    for (int i = 0; i < kNa; ++i) {
      EXPECT_EQ(actuated.M.row(i), all.M.row(kActuatedIndex[i]));
      EXPECT_EQ(actuated.NhT.row(i), all.NhT.row(kActuatedIndex[i]));
      EXPECT_EQ(actuated.JhT.row(i), all.JhT.row(kActuatedIndex[i]));
    }
    // (8): the closure is the gap between two chains of the same leg, which the base moves alike, so S_f J_h' is
    // zero up to rounding (about 1e-16 here) and the base rows drop the closure term.
    EXPECT_LT(base.JhT.cwiseAbs().maxCoeff(), 1e-12);
  });
}

TEST(DynamicsConstrained, PassiveClosedLoopMotionConservesEnergy) {
  // Zero torque, no contact, gravity on: the robot falls freely with its legs moving. RK4 at 1e-4 s for 1.5 s,
  // Baumgarte stabilisation of the closure (gains 20/s). Tolerances: |E(t) - E(0)| < 1e-7 J (about 1e-10 of the
  // 2.5 kJ exchanged between potential and kinetic energy) and closure error < 1e-10 m throughout.
  std::mt19937 rng(17);
  const PlanarModel model = buildBipedModel(robot());
  VectorQ q, qd;
  randomClosedState(rng, robot(), model, &q, &qd);
  qd *= 0.5;
  ModelData data;
  const double alpha = 20.0, beta = 20.0;
  const auto acceleration = [&](const VectorQ& x, const VectorQ& v) {
    updateModel(model, x, v, &data);
    data.Jh_dot_qd += 2.0 * alpha * data.Jh * v + beta * beta * data.closure_error;
    VectorQ a;
    constrainedForwardDynamics(data, VectorA::Zero(), VectorC::Zero(), &a, nullptr);
    return a;
  };
  const auto energy = [&](const VectorQ& x, const VectorQ& v) {
    updateModel(model, x, v, &data);
    return kineticEnergy(data, v) + potentialEnergy(model, x);
  };
  const double dt = 1e-4;
  const int steps = 15000;
  const double E0 = energy(q, qd), V0 = potentialEnergy(model, q);
  double max_energy_error = 0.0, max_closure_error = 0.0, max_exchange = 0.0;
  for (int k = 0; k < steps; ++k) {
    const VectorQ a1 = acceleration(q, qd);
    const VectorQ v2 = qd + 0.5 * dt * a1, a2 = acceleration(q + 0.5 * dt * qd, v2);
    const VectorQ v3 = qd + 0.5 * dt * a2, a3 = acceleration(q + 0.5 * dt * v2, v3);
    const VectorQ v4 = qd + dt * a3, a4 = acceleration(q + dt * v3, v4);
    q += dt / 6.0 * (qd + 2.0 * v2 + 2.0 * v3 + v4);
    qd += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    max_energy_error = std::max(max_energy_error, std::abs(energy(q, qd) - E0));
    max_closure_error = std::max(max_closure_error, data.closure_error.cwiseAbs().maxCoeff());
    max_exchange = std::max(max_exchange, std::abs(potentialEnergy(model, q) - V0));
  }
  RecordProperty("max_energy_error_J", std::to_string(max_energy_error));
  std::printf("passive run: |dE|max = %.3e J, closure max = %.3e m, |dV|max = %.1f J\n", max_energy_error,
              max_closure_error, max_exchange);
  EXPECT_GT(max_exchange, 1000.0);  // the run really exchanges energy (free fall over 1.5 s)
  EXPECT_LT(max_energy_error, 1e-7);
  EXPECT_LT(max_closure_error, 1e-10);
}

// ---------------------------------------------------------------------------------------------------------
// Real-time property
// ---------------------------------------------------------------------------------------------------------

TEST(DynamicsRealtime, UpdateModelDoesNotAllocate) {
#ifndef MFT_HAVE_MALLOC_HOOK
  GTEST_SKIP() << "allocation counter unavailable (sanitizer build or not glibc)";
#else
  std::mt19937 rng(19);
  const PlanarModel model = buildBipedModel(robot());
  std::vector<std::pair<VectorQ, VectorQ>> states(50);
  for (auto& st : states) randomClosedState(rng, robot(), model, &st.first, &st.second);
  ModelData data;
  ClosureProjection proj;
  VectorQ qdd;
  VectorH f_h;
  // The counter must see an allocation, or this test could not fail.
  g_allocations = 0;
  g_count_allocations = true;
  {
    std::vector<double> probe(1000, 1.0);
    EXPECT_GT(probe.size(), 0u);
  }
  g_count_allocations = false;
  ASSERT_GT(g_allocations.load(), 0);

  g_allocations = 0;
  g_count_allocations = true;
  for (const auto& st : states) {
    updateModel(model, st.first, st.second, &data);
    constrainedForwardDynamics(data, VectorA::Constant(1.0), VectorC::Zero(), &qdd, &f_h);
    closureProjection(data, &proj);
    const VectorA tau = inverseDynamicsActuated(data, proj, qdd, st.second, VectorC::Zero());
    (void)tau;
  }
  g_count_allocations = false;
  EXPECT_EQ(g_allocations.load(), 0);
#endif
}
