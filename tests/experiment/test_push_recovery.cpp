// The one push-recovery criterion (chain/push_recovery.hpp, docs/guide/experiments.md "Recovered") on small
// synthetic runs: recovered, fell, still drifting, and the cases at the edge of each band.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "common/strict_yaml.hpp"
#include "chain/push_recovery.hpp"
#include "chain/scenario.hpp"

namespace {

using mft::chain::RecoveryCriteria;
using mft::chain::RecoveryOutcome;
using mft::chain::RecoveryRule;
using mft::chain::RecoveryVerdict;
using mft::chain::RecoveryWindow;

constexpr double kDt = 0.001;

struct Trace {
  // Base x, z, pitch at time t; a touchdown every `step_period_s` while `stepping(t)`.
  std::function<double(double)> x = [](double) { return 0.0; };
  std::function<double(double)> z = [](double) { return 0.42; };
  std::function<double(double)> pitch = [](double) { return 0.0; };
  std::function<bool(double)> stepping = [](double) { return true; };
  double step_period_s = 0.35;
  double push_at_s = 3.0, duration_s = 8.0;
  double fall_at_s = -1.0;  // < 0: no fall
};

RecoveryVerdict judge(const Trace& tr, const RecoveryCriteria& c = {}) {
  RecoveryWindow w(c.window_s, kDt);
  std::uint64_t touchdowns = 0;
  double next_touchdown = tr.step_period_s;
  bool pushed = false;
  const auto n = static_cast<long>(std::llround(tr.duration_s / kDt));
  for (long k = 1; k <= n; ++k) {
    const double t = k * kDt;
    if (tr.fall_at_s >= 0 && t > tr.fall_at_s + 1e-9) break;  // the run stops at the fall
    if (t >= next_touchdown - 1e-9) {
      if (tr.stepping(t)) ++touchdowns;
      next_touchdown += tr.step_period_s;
    }
    if (!pushed && t >= tr.push_at_s - 1e-9) {
      w.onImpulse(t, 8.0);
      pushed = true;
    }
    mft::model::GroundTruthState s;
    s.time_s = t;
    s.q[0] = tr.x(t);
    s.q[1] = tr.z(t);
    s.q[2] = tr.pitch(t);
    s.qd[0] = (tr.x(t) - tr.x(t - kDt)) / kDt;
    s.lti = {0.8, 0.8};
    w.update(s, touchdowns);
  }
  const bool fell = tr.fall_at_s >= 0;
  return mft::chain::judgeRecovery(w.record(), c, fell, fell ? tr.fall_at_s : 0.0, fell ? "base below 0.25 m" : "");
}

// A push of a stepping robot: the base runs 0.4 m forward over 1.5 s (smoothly), dips 40 mm and pitches, then
// steps in place again.
Trace recoveredRun() {
  Trace tr;
  tr.x = [](double t) {
    if (t < 3.0) return 0.0;
    const double s = std::min(1.0, (t - 3.0) / 1.5);
    return 0.4 * (3 * s * s - 2 * s * s * s);
  };
  tr.z = [](double t) { return t < 3.0 || t > 4.5 ? 0.42 : 0.42 - 0.04 * std::sin(M_PI * (t - 3.0) / 1.5); };
  tr.pitch = [](double t) { return t < 3.0 || t > 4.5 ? 0.0 : 0.3 * std::sin(M_PI * (t - 3.0) / 1.5); };
  return tr;
}

TEST(PushRecovery, SteppingInPlaceAgainIsRecovered) {
  const auto v = judge(recoveredRun());
  EXPECT_TRUE(v.pushed);
  EXPECT_TRUE(v.no_fall);
  EXPECT_TRUE(v.back_to_stepping);
  EXPECT_TRUE(v.recovered);
  EXPECT_EQ(v.outcome, RecoveryOutcome::Recovered);
}

TEST(PushRecovery, AFallIsNeverRecoveredUnderEitherRule) {
  Trace tr = recoveredRun();
  tr.fall_at_s = 3.8;
  for (const auto rule : {RecoveryRule::BackToStepping, RecoveryRule::NoFall}) {
    RecoveryCriteria c;
    c.rule = rule;
    const auto v = judge(tr, c);
    EXPECT_FALSE(v.no_fall);
    EXPECT_FALSE(v.back_to_stepping);
    EXPECT_FALSE(v.recovered);
    EXPECT_EQ(v.outcome, RecoveryOutcome::Fell);
    EXPECT_NE(v.reason.find("fell at 3.800 s"), std::string::npos) << v.reason;
  }
}

TEST(PushRecovery, StillDriftingIsNoFallButNotRecovered) {
  Trace tr = recoveredRun();
  tr.x = [](double t) { return t < 3.0 ? 0.0 : 0.12 * (t - 3.0); };  // 0.12 m/s to the end
  auto v = judge(tr);
  EXPECT_TRUE(v.no_fall);
  EXPECT_FALSE(v.back_to_stepping);
  EXPECT_FALSE(v.recovered);
  EXPECT_EQ(v.outcome, RecoveryOutcome::Drifting);
  EXPECT_NE(v.reason.find("|mean speed| 0.120 > 0.05 m/s"), std::string::npos) << v.reason;
  // Under the no-fall rule the same run counts as recovered (the outcome stays "drifting").
  RecoveryCriteria no_fall;
  no_fall.rule = RecoveryRule::NoFall;
  v = judge(tr, no_fall);
  EXPECT_TRUE(v.recovered);
  EXPECT_EQ(v.outcome, RecoveryOutcome::Drifting);
}

TEST(PushRecovery, EachBandDecidesAlone) {
  // Speed just inside / outside 0.05 m/s.
  Trace tr = recoveredRun();
  tr.x = [](double t) { return t < 3.0 ? 0.0 : 0.049 * (t - 3.0); };
  EXPECT_TRUE(judge(tr).recovered);
  tr.x = [](double t) { return t < 3.0 ? 0.0 : 0.051 * (t - 3.0); };
  EXPECT_FALSE(judge(tr).recovered);
  // Height: the base settles 19 mm / 21 mm lower than before the push (band 20 mm).
  tr = recoveredRun();
  tr.z = [](double t) { return t < 3.0 ? 0.42 : 0.401; };
  EXPECT_TRUE(judge(tr).recovered);
  tr.z = [](double t) { return t < 3.0 ? 0.42 : 0.399; };
  auto v = judge(tr);
  EXPECT_FALSE(v.recovered);
  EXPECT_NE(v.reason.find("base height -21.0 mm"), std::string::npos) << v.reason;
  // Pitch: a rocking torso, 0.09 / 0.11 rad peaks in the last second (limit 0.1 rad).
  tr = recoveredRun();
  tr.pitch = [](double t) { return t < 5.0 ? 0.0 : 0.09 * std::sin(2 * M_PI * t); };
  EXPECT_TRUE(judge(tr).recovered);
  tr.pitch = [](double t) { return t < 5.0 ? 0.0 : 0.11 * std::sin(2 * M_PI * t); };
  EXPECT_FALSE(judge(tr).recovered);
  // Stepping: standing still (no touchdown in the last second) is not "back to stepping in place".
  tr = recoveredRun();
  tr.stepping = [](double t) { return t < 6.5; };
  v = judge(tr);
  EXPECT_FALSE(v.recovered);
  EXPECT_TRUE(v.no_fall);
  EXPECT_NE(v.reason.find("0 touchdowns in the last 1 s"), std::string::npos) << v.reason;
}

TEST(PushRecovery, TheFinalWindowMustLieAfterThePush) {
  Trace tr = recoveredRun();
  tr.push_at_s = 7.5;  // the run ends 0.5 s after the push: the last second says nothing about the push
  const auto v = judge(tr);
  EXPECT_FALSE(v.back_to_stepping);
  EXPECT_EQ(v.outcome, RecoveryOutcome::Drifting);
  tr.push_at_s = 100.0;  // never pushed
  const auto n = judge(tr);
  EXPECT_FALSE(n.pushed);
  EXPECT_FALSE(n.recovered);
  EXPECT_EQ(n.outcome, RecoveryOutcome::NotPushed);
}

TEST(PushRecovery, TheWindowIsTheLastWindowOfTheRun) {
  // A long run: only the last second counts, whatever the ring held before.
  RecoveryCriteria c;
  c.window_s = 0.5;
  c.min_touchdowns = 1;  // a step every 0.35 s: one touchdown in 0.5 s for sure
  Trace tr = recoveredRun();
  tr.x = [](double t) { return t < 7.4 ? 0.3 * t : 0.3 * 7.4; };  // moving until 7.4 s, still in the last 0.5 s
  EXPECT_TRUE(judge(tr, c).back_to_stepping);
  c.window_s = 1.0;
  EXPECT_FALSE(judge(tr, c).back_to_stepping);
}

TEST(PushRecovery, ScenarioCarriesTheCriteria) {
  const auto s = mft::chain::parseScenario(
      "schema_version: 1\nname: t\nduration_s: 8\ncontroller: mft\nestimator: kalman\nterrain: flat\n"
      "initial_base_height_m: 0.42\nfall: {base_height_below_m: 0.25, pitch_beyond_rad: 0.8}\n"
      "recovery: {rule: no_fall, window_s: 2, max_speed_mps: 0.1, height_band_m: 0.03, max_pitch_rad: 0.2, "
      "min_touchdowns: 3}\n"
      "commands:\n  - {at_s: 0, mode: stand, z_cmd_m: 0.42, v_cmd_mps: 0}\n",
      "inline");
  EXPECT_EQ(s.recovery.rule, RecoveryRule::NoFall);
  EXPECT_DOUBLE_EQ(s.recovery.window_s, 2.0);
  EXPECT_DOUBLE_EQ(s.recovery.max_speed_mps, 0.1);
  EXPECT_DOUBLE_EQ(s.recovery.height_band_m, 0.03);
  EXPECT_DOUBLE_EQ(s.recovery.max_pitch_rad, 0.2);
  EXPECT_EQ(s.recovery.min_touchdowns, 3);
  EXPECT_THROW(mft::chain::parseScenario(
                   "schema_version: 1\nname: t\nduration_s: 8\ncontroller: mft\nestimator: kalman\nterrain: flat\n"
                   "initial_base_height_m: 0.42\nfall: {base_height_below_m: 0.25, pitch_beyond_rad: 0.8}\n"
                   "recovery: {rule: maybe}\ncommands:\n  - {at_s: 0, mode: stand, z_cmd_m: 0.42, v_cmd_mps: 0}\n",
                   "inline"),
               mft::config::ConfigError);
  const RecoveryCriteria d;  // the documented defaults
  EXPECT_EQ(d.rule, RecoveryRule::BackToStepping);
  EXPECT_DOUBLE_EQ(d.window_s, 1.0);
  EXPECT_DOUBLE_EQ(d.max_speed_mps, 0.05);
  EXPECT_DOUBLE_EQ(d.height_band_m, 0.02);
  EXPECT_DOUBLE_EQ(d.max_pitch_rad, 0.1);
  EXPECT_EQ(d.min_touchdowns, 2);
}

}  // namespace
