#include "services/runtime/process.hpp"

#include <sched.h>
#include <sys/mman.h>

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
}  // namespace

bool tryRealtimeScheduling(int priority) {
  bool ok = true;
  sched_param sp{};
  sp.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
    std::fprintf(stderr, "warning: SCHED_FIFO not permitted (%s): running at normal priority\n", std::strerror(errno));
    ok = false;
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::fprintf(stderr, "warning: mlockall failed (%s): continuing without locked memory\n", std::strerror(errno));
    ok = false;
  } else {
    prefaultStack();
  }
  return ok;
}

void announceReady(const std::string& service) {
  std::printf("READY %s\n", service.c_str());
  std::fflush(stdout);
}

}  // namespace mft::services
