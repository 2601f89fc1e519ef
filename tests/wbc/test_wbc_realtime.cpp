// update() allocates nothing once constructed (counted through the global operator new of this test binary),
// and a sequence of varying ticks (stance changes, perturbations) solves every tick. A live change of weights
// and gains (setTuning, docs/guide/live-tuning.md) halfway through allocates nothing either.
#include <gtest/gtest.h>

#include <cmath>

#include "wbc/whole_body_controller.hpp"
#include "wbc_test_support.hpp"
#include "tests/support/heap_counter.hpp"

namespace mft::wbc {
namespace {

TEST(WbcRealtime, VaryingSequenceSolvesEveryTickWithoutAllocating) {
  const WbcPolytope poly = test::testPolytope();
  for (WbcVariant v : {WbcVariant::Mft, WbcVariant::Sa, WbcVariant::None}) {
    SCOPED_TRACE(toString(v));
    WholeBodyController wbc(test::robot(), test::projectConfig(v), poly);
    // Precompute the inputs (building states allocates).
    std::vector<model::RobotStateEstimate> states;
    std::vector<WbcReference> refs;
    for (int k = 0; k < 200; ++k) {
      const double t = 0.001 * k * 7;
      test::StateSpec s;
      s.base = {0.01 * std::sin(t), 0.40 + 0.02 * std::sin(2 * t), 0.05 * std::sin(3 * t)};
      s.base_vel = {0.02 * std::cos(t), 0.04 * std::cos(2 * t), 0.15 * std::cos(3 * t)};
      s.right_foot = {0.05 + 0.05 * std::sin(t), -0.40 + 0.02 * std::cos(t)};
      s.left_foot = {-0.05 - 0.05 * std::sin(t), -0.41 + 0.03 * std::sin(2 * t)};
      s.right_foot_vel = {0.05 * std::cos(t), -0.02 * std::sin(t)};
      s.left_foot_vel = {-0.05 * std::cos(t), 0.06 * std::cos(2 * t)};
      states.push_back(test::makeState(s, k));
      const int phase = (k / 50) % 3;  // double support, right stance, left stance
      refs.push_back(test::holdReference(states.back(), phase != 2, phase != 1));
      refs.back().base_z.pos = 0.40;
    }
    WbcTuning tuned = wbc.tuning();
    tuned.weights.slack = 1e5;
    tuned.weights.contact_force = 1e-4;
    tuned.gains.base_z.kp = 200.0;
    tuned.gains.swing_foot.kp = {300.0, 300.0};
    WbcDiagnostics diag;
    wbc.update(states[0], refs[0], &diag);  // warm-up tick outside the count
    g_allocations = 0;
    g_counting = true;
    int failures = 0;
    for (std::size_t k = 0; k < states.size(); ++k) {
      if (k == states.size() / 2) wbc.setTuning(tuned);
      const model::ActuatorCommand c = wbc.update(states[k], refs[k], &diag);
      failures += diag.status != qp::QpStatus::Optimal || c.mode != model::CommandMode::Normal;
    }
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0);
    EXPECT_EQ(failures, 0);
    EXPECT_EQ(diag.safety.events, 0u);
  }
}

}  // namespace
}  // namespace mft::wbc
