// The command watchdog (damping after the timeout, recovery, gap and miss counting) and the latency statistics.
#include <gtest/gtest.h>

#include <random>

#include "chain/command_watchdog.hpp"
#include "services/runtime/latency_stats.hpp"

using namespace mft::services;
using namespace mft::chain;

namespace {
constexpr std::int64_t kMs = 1'000'000;
}

constexpr std::int64_t kNone = CommandWatchdog::kNothingWaiting;

TEST(CommandWatchdog, NoDampingBeforeTheFirstCommandOrWhileCommandsFlow) {
  CommandWatchdog w(3 * kMs);
  EXPECT_FALSE(w.damping(100 * kMs, 0));  // before the first command: start-up, not a miss
  for (std::uint64_t k = 1; k <= 100; ++k) {
    const auto published = static_cast<std::int64_t>(k) * kMs;
    w.onCommand(k, published + kMs / 2);    // answered 0.5 ms after it left
    EXPECT_FALSE(w.damping(published + kMs, kNone));
  }
  EXPECT_EQ(w.deadlineMisses(), 0u);
  EXPECT_EQ(w.lostCommands(), 0u);
}

TEST(CommandWatchdog, DampsWhenATickWaitsPastTheTimeoutAndRecovers) {
  CommandWatchdog w(3 * kMs);
  w.onCommand(1, 0);
  const std::int64_t waiting_since = 1 * kMs;  // tick 2 left at 1 ms and is never answered
  EXPECT_FALSE(w.damping(4 * kMs, waiting_since));      // exactly at the timeout: still fine
  EXPECT_TRUE(w.damping(4 * kMs + 1, waiting_since));   // just past it: damping
  EXPECT_TRUE(w.damping(50 * kMs, waiting_since));      // stays damping, counted once
  EXPECT_EQ(w.deadlineMisses(), 1u);
  EXPECT_EQ(w.dampingSinceNs(), 4 * kMs + 1);
  EXPECT_EQ(w.missedDeadlineNs(), 4 * kMs);
  w.onCommand(2, 51 * kMs);
  EXPECT_FALSE(w.damping(52 * kMs, kNone));
  EXPECT_EQ(w.recoveries(), 1u);
  EXPECT_TRUE(w.damping(60 * kMs, 53 * kMs));
  EXPECT_EQ(w.deadlineMisses(), 2u);
}

// The simulator slept through 4 ms (a late wake-up) and catches up: it publishes a tick and evaluates the
// watchdog at once. The last command is 4.5 ms old, but no tick has waited for an answer: not a miss.
TEST(CommandWatchdog, ALateSimulatorWakeUpIsNotAControllerMiss) {
  CommandWatchdog w(3 * kMs);
  w.onCommand(10, 10 * kMs + kMs / 2);        // tick 10 answered 0.5 ms after it left at 10 ms
  const std::int64_t woke = 15 * kMs;         // due at 11 ms, woke at 15 ms: tick 11 leaves now
  EXPECT_FALSE(w.damping(woke, woke));
  EXPECT_FALSE(w.damping(woke + kMs / 2, woke));  // the catch-up tick right after: still within 3 ms
  EXPECT_EQ(w.deadlineMisses(), 0u);
}

// A controller that answers every tick, each 5 ms after it left: commands arrive every millisecond, yet every
// tick waits longer than the timeout. Measuring from the last arrival never noticed; this damps.
TEST(CommandWatchdog, AControllerAnsweringEveryTickTooLateIsCaught) {
  CommandWatchdog w(3 * kMs);
  bool damped = false;
  for (std::uint64_t k = 1; k <= 20; ++k) {
    const auto now = static_cast<std::int64_t>(k + 5) * kMs;
    w.onCommand(k, now);                        // the answer to tick k, 5 ms late
    damped = w.damping(now + kMs / 2, static_cast<std::int64_t>(k + 1) * kMs) || damped;  // tick k+1 waits 4.5 ms
  }
  EXPECT_TRUE(damped);
  EXPECT_GE(w.deadlineMisses(), 1u);
}

TEST(CommandWatchdog, CountsSequenceGapsAndIgnoresStaleCommands) {
  CommandWatchdog w(3 * kMs);
  w.onCommand(1, 0);
  w.onCommand(2, 1 * kMs);
  w.onCommand(6, 2 * kMs);  // 3, 4, 5 lost
  w.onCommand(4, 3 * kMs);  // late duplicate: no new gap
  w.onCommand(7, 4 * kMs);
  EXPECT_EQ(w.lostCommands(), 3u);
}

TEST(LatencyStats, MeanPercentilesAndMax) {
  LatencyStats s(100000);
  for (int i = 1; i <= 1000; ++i) s.add(i);
  EXPECT_DOUBLE_EQ(s.mean(), 500.5);
  EXPECT_DOUBLE_EQ(s.max(), 1000.0);
  EXPECT_NEAR(s.percentile(0.5), 501, 1);
  EXPECT_NEAR(s.percentile(0.99), 991, 1);
  EXPECT_NE(s.json().find("\"count\": 1000"), std::string::npos);
}

TEST(LatencyStats, BeyondCapacityMeanAndMaxStillCount) {
  LatencyStats s(10);
  for (int i = 0; i < 100; ++i) s.add(1.0);
  s.add(50.0);
  EXPECT_EQ(s.count(), 101u);
  EXPECT_DOUBLE_EQ(s.max(), 50.0);
  EXPECT_NEAR(s.mean(), 150.0 / 101.0, 1e-12);
}
