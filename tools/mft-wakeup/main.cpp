// mft-wakeup: how fast this machine wakes a thread, the floor under every hop of the chain
// (docs/loop-benchmark.md). Two probes, each thread pinned to one CPU:
//  timer:   a thread sleeps to absolute 1 kHz deadlines (clock_nanosleep, as mft-sim's realtime pacer) on each
//           CPU in turn; lateness = wake-up time - deadline (cyclictest's measure);
//  wake-up: two threads hand a token back and forth through a futex; one-way latency = from the waker's
//           FUTEX_WAKE to the woken thread running, on one core and across two cores (a chain hop on one core,
//           or on two).
// With --rt the threads run SCHED_FIFO (as the realtime stack's --rt), when permitted.
#include <linux/futex.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "common/command_line.hpp"
#include "common/json_writer.hpp"
#include "common/tool_io.hpp"

namespace {

std::int64_t nowNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

struct Stats {
  std::size_t count = 0;
  double p50 = 0, p99 = 0, max = 0, mean = 0;
};

Stats statsOf(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
  s.count = v.size();
  s.p50 = at(0.5);
  s.p99 = at(0.99);
  s.max = v.back();
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  return s;
}

// Pins the calling thread and, with `rt`, makes it SCHED_FIFO; returns whether FIFO took.
bool prepareThread(int cpu, bool rt) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (!rt) return false;
  sched_param p{};
  p.sched_priority = 80;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
}

std::vector<double> timerLateness(int cpu, int samples, std::int64_t period_ns, bool rt, bool* fifo) {
  std::vector<double> late;
  late.reserve(static_cast<std::size_t>(samples));
  std::thread t([&] {
    *fifo = prepareThread(cpu, rt);
    std::int64_t next = nowNs() + period_ns;
    for (int i = 0; i < samples; ++i) {
      timespec ts{static_cast<time_t>(next / 1000000000), static_cast<long>(next % 1000000000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
      late.push_back(static_cast<double>(nowNs() - next) * 1e-3);
      next += period_ns;
    }
  });
  t.join();
  return late;
}

long futexWait(std::atomic<int>* word, int expected) {
  return syscall(SYS_futex, reinterpret_cast<int*>(word), FUTEX_WAIT_PRIVATE, expected, nullptr, nullptr, 0);
}
void futexWake(std::atomic<int>* word) {
  syscall(SYS_futex, reinterpret_cast<int*>(word), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
}

// Ping-pong of `rounds` tokens between a thread on cpu_a and one on cpu_b; one-way latencies in us.
std::vector<double> wakeupLatency(int cpu_a, int cpu_b, int rounds, bool rt) {
  std::atomic<int> turn{0};  // even: A's turn to send, odd: B's
  std::atomic<std::int64_t> sent_at{0};
  std::vector<double> a_to_b, b_to_a;
  a_to_b.reserve(static_cast<std::size_t>(rounds));
  b_to_a.reserve(static_cast<std::size_t>(rounds));
  auto side = [&](int cpu, int my_parity, std::vector<double>* received) {
    prepareThread(cpu, rt);
    for (int i = 0; i < rounds; ++i) {
      // Wait for the token (the other side's send), blocking in the kernel as a reader thread does.
      const int expect = 2 * i + (my_parity == 0 ? 0 : 1);
      int v;
      while ((v = turn.load(std::memory_order_acquire)) != expect) futexWait(&turn, v);
      if (i > 0 || my_parity == 1) received->push_back(static_cast<double>(nowNs() - sent_at.load()) * 1e-3);
      sent_at.store(nowNs());
      turn.store(expect + 1, std::memory_order_release);
      futexWake(&turn);
    }
  };
  std::thread a(side, cpu_a, 0, &b_to_a);
  std::thread b(side, cpu_b, 1, &a_to_b);
  a.join();
  b.join();
  a_to_b.insert(a_to_b.end(), b_to_a.begin(), b_to_a.end());
  return a_to_b;
}

void writeStats(mft::config::JsonWriter& w, const char* key, const Stats& s) {
  w.key(key).beginObject().field("count", static_cast<std::uint64_t>(s.count)).field("mean", s.mean, 4)
      .field("p50", s.p50, 4).field("p99", s.p99, 4).field("max", s.max, 4).endObject();
}

int toolMain(int argc, char** argv) {
  mft::config::CommandLine cli("mft-wakeup",
                               "The machine's own wake-up latency: 1 kHz timer lateness per CPU and thread-to-thread\n"
                               "wake-ups on one core and across cores (cyclictest-like; docs/loop-benchmark.md).");
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
