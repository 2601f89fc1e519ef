#include "services/runtime/process.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <thread>

namespace mft::services {

namespace {
volatile std::sig_atomic_t g_shutdown = 0;
extern "C" void onShutdownSignal(int) { g_shutdown = 1; }
}  // namespace

void installShutdownHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onShutdownSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
bool shutdownRequested() { return g_shutdown != 0; }
void requestShutdown() { g_shutdown = 1; }
void waitForShutdown() {
  while (!shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

namespace {
// Touches the stack a service's loop may reach, so that with the memory locked its first deep call takes no page
// fault in the loop.
[[gnu::noinline]] void prefaultStack() {
  constexpr std::size_t kBytes = 256 * 1024;
  unsigned char stack[kBytes];
  for (std::size_t i = 0; i < kBytes; i += 4096) stack[i] = 0;
  asm volatile("" : : "r"(stack) : "memory");  // keeps the writes: the compiler must assume the array is read
}

struct LoopPlacement {
  std::atomic<bool> configured{false};
  int priority = 0;
  cpu_set_t cpus{};
};
LoopPlacement g_loop;

bool lockAndPrefault() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::fprintf(stderr, "warning: mlockall failed (%s): continuing without locked memory\n", std::strerror(errno));
    return false;
  }
  prefaultStack();
  return true;
}

// The machine's online CPUs outside `loop` (empty when the process may run everywhere).
cpu_set_t cpusOutside(const cpu_set_t& loop) {
  cpu_set_t others;
  CPU_ZERO(&others);
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  for (long c = 0; c < online && c < CPU_SETSIZE; ++c)
    if (!CPU_ISSET(c, &loop)) CPU_SET(c, &others);
  return others;
}
// The calling thread, and the threads it creates later, at SCHED_FIFO PRIORITY; a warning if not permitted.
bool setFifo(int priority) {
  sched_param sp{};
  sp.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) return true;
  std::fprintf(stderr, "warning: SCHED_FIFO not permitted (%s): running at normal priority\n", std::strerror(errno));
  return false;
}
}  // namespace

bool tryRealtimeScheduling(int priority) {
  const bool ok = setFifo(priority);
  return lockAndPrefault() && ok;
}

bool tryRealtimeLoopThreads(int priority) {
  bool ok = lockAndPrefault();
  if (sched_getaffinity(0, sizeof(g_loop.cpus), &g_loop.cpus) != 0) {
    std::fprintf(stderr, "warning: sched_getaffinity failed (%s): every thread realtime\n", std::strerror(errno));
    return tryRealtimeScheduling(priority) && ok;
  }
  g_loop.priority = priority;
  g_loop.configured = true;
  const cpu_set_t others = cpusOutside(g_loop.cpus);
  // A cpuset cgroup may forbid the other CPUs: the housekeeping threads then stay beside the loop, below it.
  if (CPU_COUNT(&others) > 0) sched_setaffinity(0, sizeof(others), &others);
  // SCHED_FIFO at the lowest priority: above every normal task, so that a loaded machine cannot starve a Fast DDS
  // thread while it holds a lock a loop thread's write needs (a realtime stack fell so under load at SCHED_OTHER).
  return setFifo(std::min(kHousekeepingPriority, priority)) && ok;
}

void enterLoopThread() {
  if (!g_loop.configured.load()) return;
  static std::atomic<bool> warned{false};
  pthread_setaffinity_np(pthread_self(), sizeof(g_loop.cpus), &g_loop.cpus);
  sched_param sp{};
  sp.sched_priority = g_loop.priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (rc != 0 && !warned.exchange(true))
    std::fprintf(stderr, "warning: SCHED_FIFO not permitted (%s): the loop runs at normal priority\n", std::strerror(rc));
}

void announceReady(const std::string& service) {
  std::printf("READY %s\n", service.c_str());
  std::fflush(stdout);
}

}  // namespace mft::services
