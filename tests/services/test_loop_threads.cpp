// The realtime placement of a chain service's threads (services/runtime/process.hpp): in a process confined to
// one CPU, after tryRealtimeLoopThreads the threads it starts leave that CPU at the housekeeping priority
// (SCHED_FIFO 1), and a thread that calls enterLoopThread returns to it at the loop's priority (when the
// scheduler permits SCHED_FIFO at all; otherwise every thread keeps SCHED_OTHER).
// Each case runs in a forked child: the placement is process-wide.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <thread>

#include "services/runtime/process.hpp"
#include "tests/support/child_process.hpp"

namespace {
struct Placement {
  int policy = -1;
  int priority = -1;
  cpu_set_t cpus{};
};

Placement placementOf(pthread_t thread) {
  Placement p;
  sched_param sp{};
  pthread_getschedparam(thread, &p.policy, &sp);
  p.priority = sp.sched_priority;
  pthread_getaffinity_np(thread, sizeof(p.cpus), &p.cpus);
  return p;
}

Placement placementOfNewThread(bool loop) {
  Placement p;
  std::thread([&] {
    if (loop) mft::services::enterLoopThread();
    p = placementOf(pthread_self());
  }).join();
  return p;
}

bool fifoPermitted() {
  bool ok = false;
  std::thread([&] {
    sched_param sp{};
    sp.sched_priority = 1;
    ok = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  }).join();
  return ok;
}

int firstAllowedCpu() {
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof(allowed), &allowed) != 0 || CPU_COUNT(&allowed) < 2) return -1;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &allowed)) return c;
  return -1;
}
}  // namespace

TEST(LoopThreads, OnlyTheLoopThreadsRunOnTheChainCpuAtTheLoopPriority) {
  const int chain_cpu = firstAllowedCpu();
  if (chain_cpu < 0) GTEST_SKIP() << "needs two CPUs this process may run on";
  mft::test::ForkedChild child([chain_cpu]() -> std::string {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(chain_cpu, &one);
    if (sched_setaffinity(0, sizeof(one), &one) != 0) return "cannot confine the child";
    const bool fifo = fifoPermitted();
    mft::services::tryRealtimeLoopThreads(42);
    const Placement main_thread = placementOf(pthread_self());
    const Placement other = placementOfNewThread(false);
    const Placement loop = placementOfNewThread(true);
    if (CPU_ISSET(chain_cpu, &main_thread.cpus) || CPU_COUNT(&main_thread.cpus) < 1) return "the main thread stayed";
    if (CPU_ISSET(chain_cpu, &other.cpus)) return "a thread started afterwards runs on the chain's CPU";
    if (fifo && (other.policy != SCHED_FIFO || other.priority != mft::services::kHousekeepingPriority))
      return "a thread started afterwards is not at the housekeeping priority";
    if (!fifo && other.policy != SCHED_OTHER) return "SCHED_FIFO refused, yet a thread's policy changed";
    if (CPU_COUNT(&loop.cpus) != 1 || !CPU_ISSET(chain_cpu, &loop.cpus)) return "the loop thread left the chain's CPU";
    if (fifo && (loop.policy != SCHED_FIFO || loop.priority != 42)) return "the loop thread is not SCHED_FIFO 42";
    if (!fifo && loop.policy != SCHED_OTHER) return "SCHED_FIFO refused, yet the loop thread's policy changed";
    return "ok";
  });
  ASSERT_TRUE(child.started());
  int status = 0;
  EXPECT_EQ(child.output(&status), "ok");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(LoopThreads, WithoutThePlacementEnterLoopThreadChangesNothing) {
  mft::test::ForkedChild child([]() -> std::string {
    const Placement before = placementOfNewThread(false);
    const Placement after = placementOfNewThread(true);
    if (after.policy != before.policy || !CPU_EQUAL(&after.cpus, &before.cpus)) return "the thread was moved";
    return "ok";
  });
  ASSERT_TRUE(child.started());
  int status = 0;
  EXPECT_EQ(child.output(&status), "ok");
}
