// The simulator's realtime pacer (services/sim/realtime_pacer.hpp): with or without the spin before each
// deadline it never wakes before the deadline, keeps the period, and clamps a spin longer than the period.
#include <gtest/gtest.h>

#include <chrono>

#include "services/sim/realtime_pacer.hpp"

using mft::services::RealtimePacer;
using Clock = RealtimePacer::Clock;

namespace {
// Paces `periods` 1 ms periods; true when every wake-up came at or after its deadline.
bool neverEarly(RealtimePacer& pacer, int periods) {
  pacer.start(Clock::now());
  for (int i = 0; i < periods; ++i) {
    pacer.sleep();
    if (Clock::now() < pacer.deadline()) return false;
  }
  return true;
}
}  // namespace

TEST(RealtimePacer, SleepingToTheDeadlineNeverWakesEarly) {
  RealtimePacer pacer(1e-3, 3000000);
  EXPECT_TRUE(neverEarly(pacer, 50));
}

TEST(RealtimePacer, SpinningTheLastPartNeverWakesEarlyAndKeepsThePeriod) {
  RealtimePacer pacer(1e-3, 3000000, std::chrono::microseconds(300));
  const auto t0 = Clock::now();
  EXPECT_TRUE(neverEarly(pacer, 50));
  EXPECT_GE(Clock::now() - t0, std::chrono::milliseconds(50));  // 50 deadlines of 1 ms each were waited for
  EXPECT_EQ(pacer.deadline() - t0 >= std::chrono::milliseconds(50), true);
}

TEST(RealtimePacer, ASpinLongerThanThePeriodIsClampedToIt) {
  RealtimePacer pacer(1e-3, 3000000, std::chrono::milliseconds(5));
  const auto t0 = Clock::now();
  EXPECT_TRUE(neverEarly(pacer, 20));
  const auto elapsed = Clock::now() - t0;
  EXPECT_GE(elapsed, std::chrono::milliseconds(20));
}
