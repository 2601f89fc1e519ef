// The ODE robot and the model (model/planar_dynamics) agree: for random closed-loop states and torques the
// accelerations ODE produces match the model's constrained forward dynamics (paper eq. 1).
//
// At zero velocity one small ODE step gives the acceleration exactly (forces are evaluated at the start of a
// semi-implicit Euler step and J v = 0 there). With velocity, one dWorldStep leaves out the centripetal part
// of every joint constraint (it enforces J v_{k+1} = 0, not J qdd = -Jdot qd) and recovers it over the next
// steps through the error reduction; so there the mean acceleration over a 10 ms window is compared with the
// model integrated by RK4.
#include <gtest/gtest.h>

#include <cmath>

#include "model/five_bar.hpp"
#include "model/planar_dynamics.hpp"
#include "sim/random.hpp"
#include "sim_test_support.hpp"

using namespace mft::sim;
using mft::model::VectorA;
using mft::model::VectorC;
using mft::model::VectorQ;

namespace {

SimOptions fineOptions(double h) {
  auto o = test::options();
  o.actuator_model = ActuatorModel::Ideal;  // the commanded torque acts at once, as in the model
  o.link_collisions = false;
  o.control_period_s = h;
  o.substeps = 1;
  return o;
}

// A random closed-loop state in the air: random base pose, hip angles, and (optionally) velocities.
bool randomState(const mft::model::RobotDescription& d, SplitMix64& rng, bool moving, VectorQ* q, VectorQ* qd) {
  const auto g = mft::model::FiveBarGeometry::from(d);
  auto uni = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
  q->setZero();
  qd->setZero();
  (*q)[0] = uni(-1, 1);
  (*q)[1] = 1.5;
  (*q)[2] = uni(-0.4, 0.4);
  if (moving) {
    (*qd)[0] = uni(-1, 1);
    (*qd)[1] = uni(-1, 1);
    (*qd)[2] = uni(-2, 2);
  }
  for (int leg = 0; leg < 2; ++leg) {
    const double qr = uni(-1.3, 0.2), qf = uni(-0.2, 1.3);
    mft::model::FiveBarPose p;
    if (mft::model::fiveBarForward(g, qr, qf, &p) != mft::model::FiveBarStatus::Ok) return false;
    if (std::abs(std::sin(p.knee_rear)) < 0.3 || std::abs(std::sin(p.knee_fore)) < 0.3) return false;
    if (p.knee_rear <= 0.1 || p.knee_fore >= -0.1) return false;  // the assembly mode, off the stops
    if (std::abs(std::sin(p.shank_fore - p.shank_rear)) < 0.3) return false;
    const auto c = mft::model::legCoordinates(p);
    for (int i = 0; i < 4; ++i) (*q)[3 + 4 * leg + i] = c[static_cast<std::size_t>(i)];
    if (moving) {
      const Eigen::Vector2d rates(uni(-3, 3), uni(-3, 3));
      const Eigen::Vector2d knees = mft::model::fiveBarKneeRates(g, p, rates);
      (*qd)[mft::model::hipRearIndex(leg)] = rates[0];
      (*qd)[mft::model::kneeRearIndex(leg)] = knees[0];
      (*qd)[mft::model::hipForeIndex(leg)] = rates[1];
      (*qd)[mft::model::kneeForeIndex(leg)] = knees[1];
    }
  }
  return true;
}

VectorA randomTorque(SplitMix64& rng) {
  VectorA t;
  for (int i = 0; i < 4; ++i) t[i] = -20.0 + 40.0 * rng.uniform();
  return t;
}

void commandTorques(Simulator& sim, const VectorA& tau) {
  mft::model::ActuatorCommand c;
  c.tau = tau;
  sim.setCommand(c);
}

// Draws a random state (randomState) and random torques, puts the simulator in that state and commands those
// torques. Returns false when the draw is rejected (the simulator is left as it was).
bool startFromRandomState(Simulator& sim, const mft::model::RobotDescription& d, SplitMix64& rng, bool moving,
                          VectorQ* q, VectorQ* qd, VectorA* tau) {
  if (!randomState(d, rng, moving, q, qd)) return false;
  *tau = randomTorque(rng);
  sim.setState(*q, *qd, *tau);
  commandTorques(sim, *tau);
  return true;
}

// Expects ODE's acceleration within 1e-3 of the model's (relative to its largest entry, at least 1); returns the
// largest difference.
double expectAccelerationsAgree(const VectorQ& qdd_ode, const VectorQ& qdd_model) {
  const double difference = (qdd_ode - qdd_model).cwiseAbs().maxCoeff();
  EXPECT_LT(difference, 1e-3 * std::max(1.0, qdd_model.cwiseAbs().maxCoeff()))
      << "ode   " << qdd_ode.transpose() << "\nmodel " << qdd_model.transpose();
  return difference;
}

VectorQ modelQdd(const mft::model::PlanarModel& m, const VectorQ& q, const VectorQ& qd, const VectorA& tau,
                 const VectorC& fc) {
  mft::model::ModelData data;
  mft::model::updateModel(m, q, qd, &data);
  VectorQ qdd;
  mft::model::VectorH fh;
  mft::model::constrainedForwardDynamics(data, tau, fc, &qdd, &fh);
  return qdd;
}

// Every case compares the shipped robot in ODE with its model.
class SimModelAgreement : public ::testing::Test {
 protected:
  const mft::model::RobotDescription d = test::robot();
  const mft::model::PlanarModel model = mft::model::buildBipedModel(d);
};

}  // namespace

TEST_F(SimModelAgreement, AccelerationsAtRestInTheAir) {
  const double h = 1e-4;
  Simulator sim(d, fineOptions(h), Terrain::flat());
  SplitMix64 rng(42);
  double worst = 0.0, scale = 0.0;
  int n = 0;
  while (n < 50) {
    VectorQ q, qd;
    VectorA tau;
    if (!startFromRandomState(sim, d, rng, false, &q, &qd, &tau)) continue;
    sim.step();
    const VectorQ qdd_ode = (sim.groundTruth().qd - qd) / h;
    const VectorQ qdd_model = modelQdd(model, q, qd, tau, VectorC::Zero());
    worst = std::max(worst, expectAccelerationsAgree(qdd_ode, qdd_model));
    scale = std::max(scale, qdd_model.cwiseAbs().maxCoeff());
    ++n;
  }
  std::cout << "at rest, in the air: max |qdd_ode - qdd_model| = " << worst << " (largest |qdd| " << scale << ")\n";
}

TEST_F(SimModelAgreement, AccelerationsStandingWithContactForces) {
  // On the ground: the contact forces ODE applied (measured) go into the model's eq. 1 as f_c.
  const double h = 1e-4;
  Simulator sim(d, fineOptions(h), Terrain::flat());
  SplitMix64 rng(7);
  double worst = 0.0;
  for (int n = 0; n < 20; ++n) {
    StandingPose pose;
    pose.base_height_m = 0.36 + 0.08 * rng.uniform();
    pose.pitch_rad = -0.1 + 0.2 * rng.uniform();
    pose.foot_offset_x_m = {0.1 * rng.uniform() - 0.05, 0.1 * rng.uniform() - 0.05};
    sim.reset(pose);
    const VectorQ q = sim.groundTruth().q, qd = sim.groundTruth().qd;
    commandTorques(sim, sim.seaTorque() + 5.0 * randomTorque(rng) / 20.0);
    sim.step();
    const VectorC fc = sim.groundTruth().contact_force;
    ASSERT_GT(fc[1], 10.0);
    ASSERT_GT(fc[3], 10.0);
    const VectorQ qdd_ode = (sim.groundTruth().qd - qd) / h;
    const VectorQ qdd_model = modelQdd(model, q, qd, sim.seaTorque(), fc);
    worst = std::max(worst, expectAccelerationsAgree(qdd_ode, qdd_model));
  }
  std::cout << "standing, measured contact forces: max |qdd_ode - qdd_model| = " << worst << "\n";
}

TEST_F(SimModelAgreement, MeanAccelerationsWhileMoving) {
  const double h_ode = 1e-5, window = 0.01, h_rk = 1e-4;
  Simulator sim(d, fineOptions(h_ode), Terrain::flat());
  SplitMix64 rng(3);
  double worst_rel = 0.0;
  int n = 0;
  while (n < 10) {
    VectorQ q, qd;
    VectorA tau;
    if (!startFromRandomState(sim, d, rng, true, &q, &qd, &tau)) continue;
    const int steps = static_cast<int>(std::lround(window / h_ode));
    for (int k = 0; k < steps; ++k) sim.step();
    const VectorQ mean_ode = (sim.groundTruth().qd - qd) / window;
    // RK4 on the model.
    VectorQ x = q, v = qd;
    for (int k = 0; k < static_cast<int>(std::lround(window / h_rk)); ++k) {
      const VectorQ a1 = modelQdd(model, x, v, tau, VectorC::Zero());
      const VectorQ a2 = modelQdd(model, x + 0.5 * h_rk * v, v + 0.5 * h_rk * a1, tau, VectorC::Zero());
      const VectorQ a3 = modelQdd(model, x + 0.5 * h_rk * (v + 0.5 * h_rk * a1), v + 0.5 * h_rk * a2, tau, VectorC::Zero());
      const VectorQ a4 = modelQdd(model, x + h_rk * (v + 0.5 * h_rk * a2), v + h_rk * a3, tau, VectorC::Zero());
      x += h_rk * v + h_rk * h_rk / 6.0 * (a1 + a2 + a3);
      v += h_rk / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    }
    const VectorQ mean_model = (v - qd) / window;
    const double rel = (mean_ode - mean_model).norm() / std::max(1.0, mean_model.norm());
    worst_rel = std::max(worst_rel, rel);
    EXPECT_LT(rel, 0.01) << "ode   " << mean_ode.transpose() << "\nmodel " << mean_model.transpose();
    EXPECT_LT((sim.groundTruth().q - x).cwiseAbs().maxCoeff(), 1e-4);
    ++n;
  }
  std::cout << "moving, 10 ms window: max |mean qdd_ode - mean qdd_model| / |qdd| = " << worst_rel << "\n";
}
