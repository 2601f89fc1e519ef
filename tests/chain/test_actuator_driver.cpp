// The hardware-boundary actuator driver (chain/actuator_driver.hpp): bad commands never reach an actuator and
// count as missing, the watchdog puts the actuators into damping once a published state has waited longer than
// the timeout for its command, and they resume with the next good command. Times in ns of a fake clock.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "chain/actuator_driver.hpp"

using namespace mft;
using chain::ActuatorDriver;
using chain::InputVerdict;

namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr double kPeak = 52.4;  // N m, the robot's output peak torque

chain::RawJointCommand command(std::uint64_t tick, std::uint64_t seq, double tau = 1.5, std::uint8_t mode = 0) {
  chain::RawJointCommand c;
  c.tick = tick;
  c.seq = seq;
  c.tau = {tau, -tau, 2 * tau, -2 * tau};
  c.mode = mode;
  return c;
}

}  // namespace

TEST(ActuatorDriver, DampsBeforeTheFirstCommand) {
  ActuatorDriver d(kPeak, 3 * kMs);
  d.onPublished(0, 0);
  const auto hold = d.hold(10 * kMs, 0.0);
  EXPECT_EQ(hold.command.mode, model::CommandMode::Damping);
  EXPECT_EQ(d.startupTicks(), 1u);
  EXPECT_EQ(d.dampingTicks(), 0u);
  EXPECT_EQ(d.watchdog().deadlineMisses(), 0u);  // start-up is not a miss
}

TEST(ActuatorDriver, HoldsTheNewestGoodCommandWhileAnswersAreInTime) {
  ActuatorDriver d(kPeak, 3 * kMs);
  for (std::uint64_t k = 0; k < 50; ++k) {
    const auto t = static_cast<std::int64_t>(k) * kMs;
    d.onPublished(k, t);
    ASSERT_EQ(d.receive(command(k, k + 1, 0.1 * static_cast<double>(k)), t + kMs / 2), InputVerdict::Ok);
    EXPECT_EQ(d.latencyNs(k, t + kMs / 2), kMs / 2);
    const auto hold = d.hold(t + kMs - 1, 0.001 * static_cast<double>(k));
    EXPECT_EQ(hold.command.mode, model::CommandMode::Normal);
    EXPECT_EQ(hold.command.tick, k);
    EXPECT_DOUBLE_EQ(hold.command.tau[2], 0.2 * static_cast<double>(k));
    EXPECT_EQ(hold.change, ActuatorDriver::Change::None);
  }
  EXPECT_EQ(d.commandsReceived(), 50u);
  EXPECT_EQ(d.dampingTicks(), 0u);
  EXPECT_EQ(d.watchdog().lostCommands(), 0u);
}

// Tick 1 leaves at 1 ms and is never answered: at 4 ms (exactly the 3 ms timeout) the actuators still hold the
// last command; 1 ns later they damp; the next good command ends the episode.
TEST(ActuatorDriver, WatchdogDampsAfterTheTimeoutAndResumes) {
  ActuatorDriver d(kPeak, 3 * kMs);
  d.onPublished(0, 0);
  ASSERT_EQ(d.receive(command(0, 1), kMs / 2), InputVerdict::Ok);
  d.onPublished(1, 1 * kMs);
  EXPECT_EQ(d.hold(4 * kMs, 0.001).command.mode, model::CommandMode::Normal);
  const auto onset = d.hold(4 * kMs + 1, 0.002);
  EXPECT_EQ(onset.command.mode, model::CommandMode::Damping);
  EXPECT_EQ(onset.change, ActuatorDriver::Change::DampingStarted);
  EXPECT_TRUE(onset.new_miss);
  EXPECT_NEAR(onset.onset_late_ms, 1e-6, 1e-12);  // 1 ns after the deadline
  ASSERT_EQ(d.missedDeadlinesNs().size(), 1u);
  EXPECT_EQ(d.missedDeadlinesNs()[0], 4 * kMs);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(d.hold((5 + i) * kMs, 0.003 + 0.001 * i).command.mode, model::CommandMode::Damping);
  EXPECT_EQ(d.dampingTicks(), 10u);
  EXPECT_EQ(d.watchdog().deadlineMisses(), 1u);  // one episode, one miss
  ASSERT_EQ(d.receive(command(1, 2), 14 * kMs), InputVerdict::Ok);
  const auto resumed = d.hold(14 * kMs + 1, 0.012);
  EXPECT_EQ(resumed.command.mode, model::CommandMode::Normal);
  EXPECT_EQ(resumed.change, ActuatorDriver::Change::Resumed);
  EXPECT_NEAR(resumed.damped_ms, 10.0, 1e-9);  // from 0.002 s to 0.012 s of sim time
  ASSERT_EQ(d.episodes().size(), 1u);
  EXPECT_NEAR(d.episodes()[0][0], 0.002, 1e-12);
  EXPECT_NEAR(d.episodes()[0][2], 10.0, 1e-9);
  EXPECT_EQ(d.watchdog().recoveries(), 1u);
}

TEST(ActuatorDriver, RefusesNonFiniteOutOfRangeAndUnknownModeCommands) {
  ActuatorDriver d(kPeak, 3 * kMs);
  d.onPublished(0, 0);
  ASSERT_EQ(d.receive(command(0, 1, 2.0), 100), InputVerdict::Ok);
  auto nan = command(1, 2);
  nan.tau[1] = std::numeric_limits<double>::quiet_NaN();
  auto inf = command(1, 3);
  inf.tau[3] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(d.receive(nan, 200), InputVerdict::NonFinite);
  EXPECT_EQ(d.receive(inf, 300), InputVerdict::NonFinite);
  EXPECT_EQ(d.receive(command(1, 4, kPeak * 1.01), 400), InputVerdict::OutOfRange);
  EXPECT_EQ(d.receive(command(1, 5, -kPeak * 0.5), 450), InputVerdict::Ok);  // |2 tau| = the peak: accepted
  EXPECT_EQ(d.receive(command(1, 6, 1.0, 2), 500), InputVerdict::BadEnum);
  EXPECT_EQ(d.refused(InputVerdict::NonFinite), 2u);
  EXPECT_EQ(d.refused(InputVerdict::OutOfRange), 1u);
  EXPECT_EQ(d.refused(InputVerdict::BadEnum), 1u);
  EXPECT_EQ(d.commandsReceived(), 6u);
  // The newest command is the last good one, never a refused one.
  EXPECT_EQ(d.newest().tick, 1u);
  EXPECT_DOUBLE_EQ(d.newest().tau[0], -kPeak * 0.5);
  EXPECT_EQ(d.newest().mode, model::CommandMode::Normal);
}

// A refused command counts as a missing one: when only refused commands come, the watchdog damps at the timeout.
TEST(ActuatorDriver, OnlyRefusedCommandsTripTheWatchdog) {
  ActuatorDriver d(kPeak, 3 * kMs);
  d.onPublished(0, 0);
  ASSERT_EQ(d.receive(command(0, 1), kMs / 2), InputVerdict::Ok);
  auto nan = command(0, 0);
  nan.tau[0] = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t damped = 0;
  for (std::uint64_t k = 1; k <= 10; ++k) {
    const auto t = static_cast<std::int64_t>(k) * kMs;
    d.onPublished(k, t);
    nan.tick = k;
    nan.seq = k + 1;
    EXPECT_EQ(d.receive(nan, t + kMs / 2), InputVerdict::NonFinite);
    const auto hold = d.hold(t + kMs - 1, 0.001 * static_cast<double>(k));
    EXPECT_TRUE(std::isfinite(hold.command.tau[0]));
    if (hold.command.mode == model::CommandMode::Damping) ++damped;
  }
  // Tick 1 left at 1 ms: the deadline is 4 ms, first seen past it at the hold of tick 4 (4.999 ms); ticks 4..10 damp.
  EXPECT_EQ(damped, 7u);
  EXPECT_EQ(d.dampingTicks(), 7u);
  EXPECT_EQ(d.refused(InputVerdict::NonFinite), 10u);
  EXPECT_EQ(d.watchdog().deadlineMisses(), 1u);
}

// Damping commanded by the controller itself (mode 1) is a good command and is passed on as it is.
TEST(ActuatorDriver, PassesTheControllersOwnDampingModeOn) {
  ActuatorDriver d(kPeak, 3 * kMs);
  d.onPublished(0, 0);
  ASSERT_EQ(d.receive(command(0, 1, 0.0, 1), 10), InputVerdict::Ok);
  EXPECT_TRUE(d.answers(0));
  EXPECT_FALSE(d.answers(1));
  EXPECT_EQ(d.hold(20, 0.0).command.mode, model::CommandMode::Damping);
  EXPECT_EQ(d.dampingTicks(), 0u);  // not the watchdog's
}
