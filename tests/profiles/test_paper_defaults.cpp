// The default configuration (config/*.yaml without profiles) is the paper's setup. The expected values are the
// specification, copied from the paper (Wang, Han, Ju, Zhao, "Whole-Body Control with Motion/Force
// Transmissibility for Parallel-Legged Robot"): Table I for the task weights, section IV-A for the planner
// (k_v = 0.16, k_p = 0.08, step duration 0.35 s, dt = 2 t_s with t_s = 0.025 s), section IV-B for SA-WBC's
// bounds (the singularity boundaries). They are not results and must not be edited to follow the files.
#include <gtest/gtest.h>

#include <cmath>

#include "chain/closed_loop.hpp"
#include "model/mft_raci.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft {
namespace {

const closedloop::Configs& defaults() {
  static const closedloop::Configs c = closedloop::loadConfigs(MFT_CONFIG_DIR);
  return c;
}

constexpr double kPi = 3.141592653589793;

TEST(PaperDefaults, WbcWeightsAreTableI) {
  const auto& w = defaults().wbc.weights;
  // Table I: w_z, w_theta, w_foot^sw, w_foot^st, w_fc, w_dfc, w_eps = 1, 1, 1, 1e2, 1e-3, 5e-2, 1e3.
  EXPECT_DOUBLE_EQ(w.base_z, 1.0);
  EXPECT_DOUBLE_EQ(w.base_pitch, 1.0);
  EXPECT_DOUBLE_EQ(w.swing_foot, 1.0);
  EXPECT_DOUBLE_EQ(w.support_foot, 1e2);
  EXPECT_DOUBLE_EQ(w.contact_force, 1e-3);
  EXPECT_DOUBLE_EQ(w.contact_force_rate, 5e-2);
  EXPECT_DOUBLE_EQ(w.slack, 1e3);
  EXPECT_EQ(defaults().wbc.variant, wbc::WbcVariant::Mft);
}

TEST(PaperDefaults, HorizonFrictionAndSaBounds) {
  const auto& c = defaults();
  wbc::WholeBodyController controller(c.robot, c.wbc, &c.polytope);
  // Section IV-A: dt = 2 t_s, t_s = 0.025 s (the SEA's settling time).
  EXPECT_DOUBLE_EQ(c.robot.actuator.sea.settling_time_s, 0.025);
  EXPECT_NEAR(controller.params().dt, 2.0 * 0.025, 1e-12);
  // One friction coefficient: the QP's pyramid uses the simulated ground's (robot.yaml), and the simulator does
  // not override it.
  EXPECT_DOUBLE_EQ(controller.params().mu, c.robot.friction_coefficient);
  EXPECT_FALSE(c.sim.contact_override_description);
  // Section IV-B, eq. 14: SA-WBC's q_ua^min / q_ua^max are the singularity boundaries: 0 and pi for the rear
  // knees, -pi and 0 for the fore knees, i.e. the robot's knee ranges themselves.
  EXPECT_DOUBLE_EQ(c.wbc.sa.rear_knee_rad.lo, 0.0);
  EXPECT_NEAR(c.wbc.sa.rear_knee_rad.hi, kPi, 1e-15);
  EXPECT_NEAR(c.wbc.sa.fore_knee_rad.lo, -kPi, 1e-15);
  EXPECT_DOUBLE_EQ(c.wbc.sa.fore_knee_rad.hi, 0.0);
  EXPECT_DOUBLE_EQ(c.wbc.sa.rear_knee_rad.lo, c.robot.rear_knee_rad.lo);
  EXPECT_DOUBLE_EQ(c.wbc.sa.fore_knee_rad.hi, c.robot.fore_knee_rad.hi);
}

TEST(PaperDefaults, PlannerGainsAreThePapers) {
  const auto& p = defaults().planner;
  // Section IV-A, eq. 13: k_v = 0.16, k_p = 0.08; nominal step duration 0.35 s.
  EXPECT_DOUBLE_EQ(p.placement.k_v, 0.16);
  EXPECT_DOUBLE_EQ(p.placement.k_p, 0.08);
  EXPECT_DOUBLE_EQ(p.gait.step_duration_s, 0.35);
}

TEST(PaperDefaults, SimulatorUsesThePhysicalSeaWithTheRaciRotor) {
  const auto& c = defaults();
  EXPECT_EQ(c.sim.actuator_model, sim::ActuatorModel::SeaMotor);
  // One rotor inertia: the MFT space's RACI threshold T_m,max / sqrt(J_m) in the polytope file is the one that
  // robot.yaml's J_m gives (the simulator's motor side reads the same J_m: sim/simulator.cpp, n^2 J_m).
  EXPECT_NEAR(c.polytope.criteria.raci.hi, model::actuatorRaciLimit(c.robot.actuator), 0.01);
  EXPECT_NEAR(c.polytope.criteria.raci.hi, 174.54, 0.01);  // the paper's threshold
}

}  // namespace
}  // namespace mft
