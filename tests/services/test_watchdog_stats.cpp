// The command watchdog (damping after the timeout, recovery, gap and miss counting) and the latency statistics.
#include <gtest/gtest.h>

#include <random>

#include "services/runtime/command_watchdog.hpp"
#include "services/runtime/latency_stats.hpp"

using namespace mft::services;

namespace {
constexpr std::int64_t kMs = 1'000'000;
}

TEST(CommandWatchdog, NoDampingBeforeTheFirstCommandOrWhileCommandsFlow) {
  CommandWatchdog w(3 * kMs);
  EXPECT_FALSE(w.damping(100 * kMs));
  for (std::uint64_t k = 1; k <= 100; ++k) {
    w.onCommand(k, static_cast<std::int64_t>(k) * kMs);
    EXPECT_FALSE(w.damping(static_cast<std::int64_t>(k) * kMs + kMs / 2));
  }
  EXPECT_EQ(w.deadlineMisses(), 0u);
  EXPECT_EQ(w.lostCommands(), 0u);
}

TEST(CommandWatchdog, DampsAfterTheTimeoutAndRecovers) {
  CommandWatchdog w(3 * kMs);
  w.onCommand(1, 0);
  EXPECT_FALSE(w.damping(3 * kMs));       // exactly at the timeout: still fine
  EXPECT_TRUE(w.damping(3 * kMs + 1));    // just past it: damping
  EXPECT_TRUE(w.damping(50 * kMs));       // stays damping, counted once
  EXPECT_EQ(w.deadlineMisses(), 1u);
  EXPECT_EQ(w.dampingSinceNs(), 3 * kMs + 1);
  w.onCommand(2, 51 * kMs);
  EXPECT_FALSE(w.damping(52 * kMs));
  EXPECT_EQ(w.recoveries(), 1u);
  EXPECT_TRUE(w.damping(60 * kMs));
  EXPECT_EQ(w.deadlineMisses(), 2u);
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
