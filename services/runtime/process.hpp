#pragma once
// Process-level plumbing shared by the service mains: shutdown on SIGINT/SIGTERM, optional real-time
// scheduling with a graceful fallback, the readiness line the supervisor waits for, and the strict
// command-line parser (common/command_line.hpp: unknown options are errors, every service has --help).
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "common/command_line.hpp"

namespace mft::services {

// Installs SIGINT/SIGTERM handlers that only set a flag (async-signal-safe).
void installShutdownHandlers();
bool shutdownRequested();
void requestShutdown();
// Returns once shutdown is requested (looked at every 10 ms): the main thread of a service whose work runs in
// its DDS callbacks.
void waitForShutdown();

// Ends a worker thread that sleeps on `wake` until it has work or `stop` (set here under `mutex`), and joins it.
inline void stopWorker(std::mutex& mutex, bool& stop, std::condition_variable& wake, std::thread& worker) {
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
  }
  wake.notify_all();
  worker.join();
}

// Tries SCHED_FIFO at `priority` and mlockall; on failure prints a warning to stderr and carries on.
// Returns true when both took effect. Call before creating the DDS participant so its threads inherit it.
bool tryRealtimeScheduling(int priority);

// The realtime placement of a chain service on the shared-memory channel, where the 1 kHz work runs on threads
// the service owns: only those take SCHED_FIFO at `priority`, each as it starts (enterLoopThread()), on the CPUs
// the process was started on (the supervisor's chain CPU). Every other thread (the main thread waiting for
// shutdown, DDS's own threads, created after this call) runs at SCHED_FIFO kHousekeepingPriority and leaves those
// CPUs when the machine has others, so nothing but the chain wakes up on the chain's core
// (measured: docs/results/loop-benchmark.md). Locks memory as tryRealtimeScheduling. Call before creating the DDS
// participant. Returns true when all took effect.
constexpr int kHousekeepingPriority = 1;
bool tryRealtimeLoopThreads(int priority);
// After tryRealtimeLoopThreads: the calling thread becomes a loop thread (SCHED_FIFO on the chain's CPUs);
// otherwise it does nothing. Warns once if the scheduler refuses.
void enterLoopThread();

// The line the supervisor waits for on stdout: "READY <service>".
void announceReady(const std::string& service);

// The command-line parser under the name the services and DDS tools use.
using config::CommandLine;

}  // namespace mft::services
