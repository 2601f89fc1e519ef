// Passive swing with the torso fixed: the legs' mechanical energy is conserved within 2 %.
#include <gtest/gtest.h>

#include <cmath>

#include "model/five_bar.hpp"
#include "sim_test_support.hpp"

using namespace mft::sim;
using mft::model::VectorQ;

namespace {
// Initial state: stance-shaped legs swinging at the given hip rates, knee rates through the loop closure.
void swingState(const mft::model::RobotDescription& d, VectorQ* q, VectorQ* qd) {
  const auto g = mft::model::FiveBarGeometry::from(d);
  q->setZero();
  qd->setZero();
  (*q)[1] = 1.5;
  const double hip[2][2] = {{-0.64, 0.64}, {-0.5, 0.8}};
  const double rate[2][2] = {{2.0, 1.4}, {-1.5, 1.0}};
  for (int leg = 0; leg < 2; ++leg) {
    mft::model::FiveBarPose p;
    mft::model::fiveBarForward(g, hip[leg][0], hip[leg][1], &p);
    const auto c = mft::model::legCoordinates(p);
    const Eigen::Vector2d knee_rates = mft::model::fiveBarKneeRates(g, p, Eigen::Vector2d(rate[leg][0], rate[leg][1]));
    for (int i = 0; i < 4; ++i) (*q)[3 + 4 * leg + i] = c[static_cast<std::size_t>(i)];
    (*qd)[mft::model::hipRearIndex(leg)] = rate[leg][0];
    (*qd)[mft::model::kneeRearIndex(leg)] = knee_rates[0];
    (*qd)[mft::model::hipForeIndex(leg)] = rate[leg][1];
    (*qd)[mft::model::kneeForeIndex(leg)] = knee_rates[1];
  }
}
}  // namespace

TEST(SimEnergy, PassiveSwingWithFixedTorso) {
  // A conservative spring between the two thighs of each leg (applied through ideal actuators every physics
  // step, its energy counted) keeps each five-bar away from its singular stretch, as in docs/reference/simulation.md#five-bar-singularity-and-energy: a hanging
  // five-bar would otherwise fall onto its knee stops, which are deliberately lossy.
  const double k = 30.0;
  for (double period : {0.001, 0.00025}) {
    auto o = test::options();
    o.fix_torso = true;
    o.link_collisions = false;
    o.actuator_model = ActuatorModel::Ideal;
    o.control_period_s = period;
    o.substeps = 1;
    Simulator sim(test::robot(), o, Terrain::flat());
    VectorQ q, qd;
    swingState(sim.robot(), &q, &qd);
    double open0[2];
    for (int leg = 0; leg < 2; ++leg) open0[leg] = q[mft::model::hipForeIndex(leg)] - q[mft::model::hipRearIndex(leg)];
    auto spring = [&](const VectorQ& x, mft::model::VectorA* tau) {
      double e = 0.0;
      for (int leg = 0; leg < 2; ++leg) {
        const double dev = x[mft::model::hipForeIndex(leg)] - x[mft::model::hipRearIndex(leg)] - open0[leg];
        (*tau)[2 * leg] = k * dev;
        (*tau)[2 * leg + 1] = -k * dev;
        e += 0.5 * k * dev * dev;
      }
      return e;
    };
    mft::model::VectorA tau;
    const double spring0 = spring(q, &tau);
    sim.setState(q, qd, tau);
    const double e0 = sim.mechanicalEnergy() + spring0;
    double max_dev = 0.0, min_knee_margin = 1e9;
    const int steps = static_cast<int>(std::lround(5.0 / period));
    for (int i = 0; i < steps; ++i) {
      mft::model::ActuatorCommand c;
      spring(sim.groundTruth().q, &c.tau);
      sim.setCommand(c);
      sim.step();
      const VectorQ& x = sim.groundTruth().q;
      max_dev = std::max(max_dev, std::abs(sim.mechanicalEnergy() + spring(x, &tau) - e0));
      for (int leg = 0; leg < 2; ++leg)  // distance of the knees from their singular values 0 and pi
        for (int idx : {mft::model::kneeRearIndex(leg), mft::model::kneeForeIndex(leg)})
          min_knee_margin = std::min({min_knee_margin, std::abs(x[idx]), M_PI - std::abs(x[idx])});
    }
    // Reference: the kinetic energy at the start (both legs swinging).
    Simulator ref(test::robot(), o, Terrain::flat());
    ref.setState(q, VectorQ::Zero(), tau);
    const double kinetic0 = e0 - (ref.mechanicalEnergy() + spring0);
    std::cout << "control period " << period << " s: max |E - E0| = " << max_dev << " J = " << 100.0 * max_dev / kinetic0
              << " % of the initial kinetic energy " << kinetic0 << " J; final drift "
              << 100.0 * (sim.mechanicalEnergy() + spring(sim.groundTruth().q, &tau) - e0) / kinetic0 << " %\n";
    std::cout << "  closest knee approach to a singular value: " << min_knee_margin << " rad\n";
    EXPECT_GT(min_knee_margin, sim.robot().knee_hard_stop_margin_rad);  // no lossy hard-stop contact
    EXPECT_LT(max_dev, 0.02 * kinetic0);
    EXPECT_EQ(sim.stats().ode_messages, 0u);
  }
}
