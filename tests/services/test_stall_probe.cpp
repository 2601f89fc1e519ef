// The CPU stall probe (services/runtime/stall_probe.hpp): the union of stalls within a window, the ring
// keeping the newest, one thread per CPU, and a real stall (the process stopped by SIGSTOP) recorded.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "services/runtime/stall_probe.hpp"
#include "tests/support/child_process.hpp"

using mft::services::StallProbe;

namespace {
StallProbe::Options idleProbe() {
  StallProbe::Options o;
  o.period = std::chrono::microseconds(100000);  // the live threads stay out of the way of these tests
  o.threshold = std::chrono::microseconds(50000000);
  o.capacity = 4;
  return o;
}
}  // namespace

TEST(StallProbe, StalledTimeIsTheUnionOfTheStallsInTheWindow) {
  StallProbe probe(idleProbe());
  probe.recordStall(10, 20);
  probe.recordStall(15, 30);  // overlaps the first (two CPUs stalled at once count once)
  probe.recordStall(50, 60);
  EXPECT_EQ(probe.stalledWithinNs(0, 100), 30);
  EXPECT_EQ(probe.stalledWithinNs(18, 55), 12 + 5);
  EXPECT_EQ(probe.stalledWithinNs(30, 50), 0);
  EXPECT_EQ(probe.stalledWithinNs(60, 10), 0);
  EXPECT_EQ(probe.stalls(), 3u);
  EXPECT_DOUBLE_EQ(probe.maxStallMs(), 15e-6);
  EXPECT_DOUBLE_EQ(probe.totalStallMs(), 35e-6);
}

TEST(StallProbe, JudgesAMissByTheStallsWhileTheTickWaited) {
  StallProbe probe(idleProbe());  // period 100 ms: the window reaches one period past each end
  const std::int64_t ms = 1000000, period = 100 * ms, timeout = 3 * ms, deadline = 1000 * ms;
  probe.recordStall(deadline - timeout - period - 5 * ms, deadline - timeout - period - 1 * ms);  // before: not counted
  EXPECT_EQ(probe.stalledWhileWaitingNs(deadline, timeout), 0);
  probe.recordStall(deadline + period - ms, deadline + period + 9 * ms);  // recorded up to a period late
  EXPECT_EQ(probe.stalledWhileWaitingNs(deadline, timeout), ms);
  EXPECT_FALSE(StallProbe::explainsMiss(ms, timeout));
  EXPECT_TRUE(StallProbe::explainsMiss(timeout / 2, timeout));
}

TEST(StallProbe, KeepsTheNewestStallsWhenFull) {
  StallProbe probe(idleProbe());  // capacity 4
  for (int i = 0; i < 6; ++i) probe.recordStall(100 * i, 100 * i + 10);
  EXPECT_EQ(probe.stalledWithinNs(0, 200), 0);        // the two oldest are gone
  EXPECT_EQ(probe.stalledWithinNs(200, 600), 40);
  EXPECT_EQ(probe.stalls(), 6u);                      // but counted
}

TEST(StallProbe, OneThreadPerCpuOfTheMachineEvenWhenThisThreadIsPinned) {
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  {
    StallProbe probe(idleProbe());
    EXPECT_EQ(probe.cpus(), CPU_COUNT(&set));
  }
  // A realtime stack pins the simulator to the chain's core; its probe still watches every CPU.
  cpu_set_t one;
  CPU_ZERO(&one);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) {
      CPU_SET(cpu, &one);
      break;
    }
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  {
    StallProbe probe(idleProbe());
    EXPECT_EQ(probe.cpus(), CPU_COUNT(&set));
  }
  ASSERT_EQ(sched_setaffinity(0, sizeof set, &set), 0);
}

// A child runs a probe (1 ms period, 5 ms threshold) and is stopped for 40 ms: every CPU's thread wakes at
// least ~35 ms late. It reports its stalls through a pipe.
TEST(StallProbe, RecordsTheProcessBeingStopped) {
  mft::test::ForkedChild child([] {
    double result[2] = {0, 0};
    {
      StallProbe::Options o;
      o.period = std::chrono::microseconds(1000);
      o.threshold = std::chrono::microseconds(5000);
      StallProbe probe(o);
      std::this_thread::sleep_for(std::chrono::milliseconds(400));
      result[0] = static_cast<double>(probe.stalls());
      result[1] = probe.maxStallMs();
    }
    return std::string(reinterpret_cast<const char*>(result), sizeof result);
  });
  ASSERT_TRUE(child.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  kill(child.pid(), SIGSTOP);
  std::this_thread::sleep_for(std::chrono::milliseconds(40));
  kill(child.pid(), SIGCONT);
  int status = 0;
  const std::string out = child.output(&status);
  double result[2] = {0, 0};
  ASSERT_EQ(out.size(), sizeof result);
  std::memcpy(result, out.data(), sizeof result);
  EXPECT_GE(result[0], 1.0);
  EXPECT_GE(result[1], 30.0);
}
