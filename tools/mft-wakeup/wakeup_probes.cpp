#include "tools/mft-wakeup/wakeup_probes.hpp"

#include <linux/futex.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <thread>

namespace mft::wakeup {

static std::int64_t nowNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

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
static bool prepareThread(int cpu, bool rt) {
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

static long futexWait(std::atomic<int>* word, int expected) {
  return syscall(SYS_futex, reinterpret_cast<int*>(word), FUTEX_WAIT_PRIVATE, expected, nullptr, nullptr, 0);
}
static void futexWake(std::atomic<int>* word) {
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

}  // namespace mft::wakeup
