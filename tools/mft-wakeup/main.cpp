// mft-wakeup: how fast this machine wakes a thread, the floor under every hop of the chain
// (docs/results/loop-benchmark.md). Two probes, each thread pinned to one CPU:
//  timer:   a thread sleeps to absolute 1 kHz deadlines (clock_nanosleep, as mft-sim's realtime pacer) on each
//           CPU in turn; lateness = wake-up time - deadline (cyclictest's measure);
//  wake-up: two threads hand a token back and forth through a futex; one-way latency = from the waker's
//           FUTEX_WAKE to the woken thread running, on one core and across two cores (a chain hop on one core,
//           or on two).
// With --rt the threads run SCHED_FIFO (as the realtime stack's --rt), when permitted.
#include <sched.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "common/command_line.hpp"
#include "common/json_writer.hpp"
#include "common/tool_io.hpp"
#include "tools/mft-wakeup/wakeup_probes.hpp"

using namespace mft::wakeup;

namespace {

void writeStats(mft::config::JsonWriter& w, const char* key, const Stats& s) {
  w.key(key).beginObject().field("count", static_cast<std::uint64_t>(s.count)).field("mean", s.mean, 4)
      .field("p50", s.p50, 4).field("p99", s.p99, 4).field("max", s.max, 4).endObject();
}

int toolMain(int argc, char** argv) {
  mft::config::CommandLine cli("mft-wakeup",
                               "The machine's own wake-up latency: 1 kHz timer lateness per CPU and thread-to-thread\n"
                               "wake-ups on one core and across cores (cyclictest-like; docs/results/loop-benchmark.md).");
  cli.option("timer-samples", "1 kHz timer wake-ups per CPU", "2000");
  cli.option("wakeups", "token hand-offs per placement (one core, two cores)", "5000");
  cli.flag("rt", "run the probe threads SCHED_FIFO 80 (as the realtime stack's --rt), when permitted");
  cli.flag("json", "print the figures as JSON");
  cli.parse(argc, argv);
  const int timer_samples = static_cast<int>(cli.getInt("timer-samples", 10, 1000000));
  const int wakeups = static_cast<int>(cli.getInt("wakeups", 10, 10000000));
  const bool rt = cli.isSet("rt");
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) cli.fail(std::string("sched_getaffinity: ") + std::strerror(errno));
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &allowed)) cpus.push_back(c);

  bool fifo = false;
  std::vector<std::pair<int, Stats>> timer;
  for (int c : cpus) timer.emplace_back(c, statsOf(timerLateness(c, timer_samples, 1000000, rt, &fifo)));
  const Stats same = statsOf(wakeupLatency(cpus.front(), cpus.front(), wakeups, rt));
  const bool two = cpus.size() > 1;
  const Stats cross = two ? statsOf(wakeupLatency(cpus[0], cpus[1], wakeups, rt)) : Stats{};

  if (cli.isSet("json")) {
    mft::config::JsonWriter w;
    w.beginObject().field("scheduling", fifo ? "SCHED_FIFO 80" : "SCHED_OTHER").key("timer_late_us").beginObject();
    for (const auto& [c, s] : timer) writeStats(w, ("cpu" + std::to_string(c)).c_str(), s);
    w.endObject().key("wakeup_us").beginObject();
    writeStats(w, "same_core", same);
    if (two) writeStats(w, "cross_core", cross);
    w.endObject().endObject();
    std::printf("%s\n", w.str().c_str());
    return 0;
  }
  std::printf("scheduling: %s\n", fifo ? "SCHED_FIFO 80" : "SCHED_OTHER (no --rt, or not permitted)");
  for (const auto& [c, s] : timer)
    std::printf("1 kHz timer on cpu %d: late p50 %.1f us, p99 %.1f us, max %.1f us (%zu wake-ups)\n", c, s.p50, s.p99,
                s.max, s.count);
  std::printf("thread wake-up, one core:   p50 %.1f us, p99 %.1f us, max %.1f us\n", same.p50, same.p99, same.max);
  if (two) std::printf("thread wake-up, two cores:  p50 %.1f us, p99 %.1f us, max %.1f us\n", cross.p50, cross.p99, cross.max);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-wakeup", [&] { return toolMain(argc, argv); });
}
