// Contact schedule: alternation, early / late / forced touchdown, early-contact lockout, double support, stop.
#include <gtest/gtest.h>

#include "planner/contact_schedule.hpp"

using namespace mft::planner;
using Contacts = std::array<bool, 2>;

namespace {
GaitParams gait(double ds = 0.0) {
  GaitParams g;
  g.step_duration_s = 0.35;
  g.double_support_s = ds;
  g.min_touchdown_phase = 0.6;
  g.max_extension_s = 0.1;
  g.first_swing_leg = 0;
  return g;
}
constexpr double kDt = 0.001;

// Runs the schedule with an ideal robot whose swing foot lands exactly at `touchdown_after` seconds of swing.
struct Sim {
  ContactSchedule sched;
  double t = 0.0;
  explicit Sim(const GaitParams& g) : sched(g) { sched.reset(0.0); }
  ScheduleEvents tick(double touchdown_after, bool stepping = true) {
    Contacts c{true, true};
    if (sched.inSwing() && sched.timeInSwing() + kDt < touchdown_after - 1e-9) c[sched.swingLeg()] = false;
    t += kDt;
    return sched.update(t, c, stepping);
  }
};
}  // namespace

TEST(ContactSchedule, StartsStandingAndStaysSoWithoutStepping) {
  ContactSchedule s(gait());
  s.reset(0.0);
  for (int i = 1; i < 100; ++i) s.update(i * kDt, {true, true}, false);
  EXPECT_FALSE(s.inSwing());
  EXPECT_EQ(s.stanceLeg(), -1);
  EXPECT_EQ(s.stepIndex(), 0u);
  EXPECT_DOUBLE_EQ(s.phase(), 0.0);
}

TEST(ContactSchedule, LegsAlternateAtTheNominalDuration) {
  Sim sim(gait());
  std::vector<int> swing_legs;
  std::vector<double> liftoff_times;
  while (sim.t < 2.0) {
    const auto ev = sim.tick(0.35);
    if (ev.liftoff_leg >= 0) {
      swing_legs.push_back(ev.liftoff_leg);
      liftoff_times.push_back(sim.t);
    }
    if (sim.sched.inSwing()) {
      EXPECT_EQ(sim.sched.stanceLeg(), 1 - sim.sched.swingLeg());
      EXPECT_GE(sim.sched.phase(), 0.0);
      EXPECT_LE(sim.sched.phase(), 1.0);
    }
  }
  ASSERT_GE(swing_legs.size(), 5u);
  for (std::size_t i = 0; i < swing_legs.size(); ++i) EXPECT_EQ(swing_legs[i], static_cast<int>(i % 2));
  for (std::size_t i = 1; i < liftoff_times.size(); ++i) EXPECT_NEAR(liftoff_times[i] - liftoff_times[i - 1], 0.35, 1.5 * kDt);
  EXPECT_EQ(sim.sched.stepIndex(), swing_legs.size());
}

TEST(ContactSchedule, EarlyTouchdownEndsTheSwing) {
  Sim sim(gait());
  sim.tick(0.25);  // lift-off of the right leg
  ASSERT_EQ(sim.sched.swingLeg(), 0);
  ScheduleEvents ev;
  while (ev.touchdown_leg < 0) ev = sim.tick(0.25);
  EXPECT_EQ(ev.touchdown_leg, 0);
  EXPECT_EQ(ev.liftoff_leg, 1);  // no double support: the other leg lifts in the same update
  EXPECT_EQ(sim.sched.lastTouchdown(), TouchdownKind::Early);
  EXPECT_NEAR(sim.t, kDt + 0.25, 1.5 * kDt);
}

TEST(ContactSchedule, ContactBeforeTheMinimumPhaseIsIgnored) {
  ContactSchedule s(gait());
  s.reset(0.0);
  s.update(0.001, {true, true}, true);  // lift-off right; switch still closed from stance
  ASSERT_EQ(s.swingLeg(), 0);
  for (double t = 0.002; t < 0.6 * 0.35 - 0.002; t += kDt) {
    const auto ev = s.update(t, {true, true}, true);
    EXPECT_LT(ev.touchdown_leg, 0) << t;
  }
  const auto ev = s.update(0.001 + 0.6 * 0.35 + 1e-9, {true, true}, true);
  EXPECT_EQ(ev.touchdown_leg, 0);
}

TEST(ContactSchedule, LateTouchdownExtendsTheSwing) {
  Sim sim(gait());
  sim.tick(0.40);
  ScheduleEvents ev;
  bool saw_extension = false;
  while (ev.touchdown_leg < 0) {
    ev = sim.tick(0.40);
    if (sim.sched.extended()) {
      saw_extension = true;
      EXPECT_DOUBLE_EQ(sim.sched.phase(), 1.0);
    }
  }
  EXPECT_TRUE(saw_extension);
  EXPECT_EQ(sim.sched.lastTouchdown(), TouchdownKind::Late);
  EXPECT_NEAR(sim.t, kDt + 0.40, 1.5 * kDt);
}

TEST(ContactSchedule, MissingContactForcesTheSwapAfterTheExtension) {
  Sim sim(gait());
  sim.tick(10.0);
  ScheduleEvents ev;
  while (ev.touchdown_leg < 0) ev = sim.tick(10.0);
  EXPECT_EQ(sim.sched.lastTouchdown(), TouchdownKind::Forced);
  EXPECT_NEAR(sim.t, kDt + 0.35 + 0.1, 1.5 * kDt);
}

TEST(ContactSchedule, DoubleSupportDelaysTheNextLiftoff) {
  Sim sim(gait(0.05));
  sim.tick(0.35);
  double touchdown_time = -1, liftoff_time = -1;
  while (liftoff_time < 0) {
    const auto ev = sim.tick(0.35);
    if (ev.touchdown_leg >= 0) {
      touchdown_time = sim.t;
      EXPECT_EQ(sim.sched.stanceLeg(), -1);
    }
    if (ev.liftoff_leg >= 0) liftoff_time = sim.t;
  }
  EXPECT_NEAR(liftoff_time - touchdown_time, 0.05, 1.5 * kDt);
}

TEST(ContactSchedule, StoppingFinishesTheCurrentStep) {
  Sim sim(gait());
  sim.tick(0.30);
  ASSERT_TRUE(sim.sched.inSwing());
  for (int i = 0; i < 1000; ++i) sim.tick(0.30, false);
  EXPECT_FALSE(sim.sched.inSwing());
  EXPECT_EQ(sim.sched.stepIndex(), 1u);
  EXPECT_EQ(sim.sched.lastTouchdown(), TouchdownKind::Early);  // landed on contact before T
}
