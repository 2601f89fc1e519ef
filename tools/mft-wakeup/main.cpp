// mft-wakeup: the machine's own wake-up latency, the floor under every hop of the control chain.
// A cyclictest-like probe: how late a SCHED_FIFO thread wakes from an absolute timer on each CPU, and how long
// one process takes to wake another that sleeps (a futex in shared memory, as a condition-variable hand-off; a
// UDP datagram on loopback, as a DDS hop), with both on one CPU and on two. The chain's realtime latency is
// judged against these figures (docs/loop-benchmark.md). Exit status: 0, 2 on bad options, 3 when a case fails.
#include <linux/futex.h>
#include <netinet/in.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/config/json_writer.hpp"
#include "model/config/tool_io.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/process.hpp"

namespace {

using mft::services::LatencyStats;

std::int64_t nowNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void sleepUntilNs(std::int64_t t) {
  timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void pinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof(set), &set) != 0)
    throw std::runtime_error("cannot pin to CPU " + std::to_string(cpu) + ": " + std::strerror(errno));
}

// SCHED_FIFO for the calling thread when permitted (a measurement without it says so).
bool tryFifo(int priority) {
  sched_param p{};
  p.sched_priority = priority;
  return sched_setscheduler(0, SCHED_FIFO, &p) == 0;
}

struct Options {
  int samples = 3000;
  long period_us = 1000;
  int priority = 80;
  bool fifo = true;
};

struct CaseResult {
  std::string kind;  // timer | futex | udp
  int from_cpu = -1, to_cpu = -1;
  LatencyStats latency_us;
  bool fifo = false;
  std::string error;
  explicit CaseResult(std::size_t n) : latency_us(n) {}
};

// Timer lateness on one CPU: sleep to an absolute deadline every period, record how late the thread ran.
void timerCase(const Options& o, CaseResult& r) {
  pinTo(r.to_cpu);
  r.fifo = o.fifo && tryFifo(o.priority);
  std::int64_t next = nowNs() + 10'000'000;
  for (int i = 0; i < o.samples; ++i) {
    sleepUntilNs(next);
    r.latency_us.add(static_cast<double>(nowNs() - next) * 1e-3);
    next += o.period_us * 1000;
  }
  sched_param normal{};
  sched_setscheduler(0, SCHED_OTHER, &normal);
}

// Shared between the waker (this process) and the sleeper (a forked child): a sequence number the sleeper
// waits on with a futex, and the waker's stamp of each wake-up.
struct SharedWake {
  std::atomic<std::uint32_t> seq{0};
  std::atomic<std::int64_t> stamp_ns{0};
  std::atomic<std::uint32_t> taken{0};  // wake-ups the sleeper has recorded: one stamp is never overwritten unread
};
static_assert(std::atomic<std::uint32_t>::is_always_lock_free, "futex word must be a plain 32-bit int");

long futexCall(std::atomic<std::uint32_t>* word, int op, std::uint32_t value) {
  return syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), op, value, nullptr, nullptr, 0);
}

// Reads exactly n bytes from fd (the child's latencies), waiting at most until deadline_ns.
bool readAll(int fd, void* data, std::size_t n, std::int64_t deadline_ns) {
  auto* p = static_cast<char*>(data);
  while (n > 0) {
    pollfd pfd{fd, POLLIN, 0};
    const std::int64_t left_ms = (deadline_ns - nowNs()) / 1'000'000;
    if (left_ms <= 0 || poll(&pfd, 1, static_cast<int>(left_ms)) == 0) return false;
    const ssize_t k = read(fd, p, n);
    if (k <= 0) {
      if (k < 0 && errno == EINTR) continue;
      return false;
    }
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

// One process wakes another every period; the sleeper records now - stamp. kind: "futex" or "udp".
void pairCase(const Options& o, CaseResult& r) {
  auto* shared = static_cast<SharedWake*>(
      mmap(nullptr, sizeof(SharedWake), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0));
  if (shared == MAP_FAILED) throw std::runtime_error(std::string("mmap: ") + std::strerror(errno));
  new (shared) SharedWake();
  const bool udp = r.kind == "udp";
  int rx = -1, tx = -1;
  sockaddr_in addr{};
  if (udp) {
    rx = socket(AF_INET, SOCK_DGRAM, 0);
    tx = socket(AF_INET, SOCK_DGRAM, 0);
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    socklen_t len = sizeof(addr);
    if (rx < 0 || tx < 0 || bind(rx, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
        getsockname(rx, reinterpret_cast<sockaddr*>(&addr), &len) != 0)
      throw std::runtime_error(std::string("loopback UDP socket: ") + std::strerror(errno));
  }
  int pipe_fd[2];
  if (pipe(pipe_fd) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (child == 0) {  // the sleeper: wake, stamp, sleep again; send the latencies back at the end
    close(pipe_fd[0]);
    std::vector<double> lat(static_cast<std::size_t>(o.samples));
    int fifo = 0;
    try {
      pinTo(r.to_cpu);
      fifo = o.fifo && tryFifo(o.priority) ? 1 : 0;
    } catch (const std::exception&) {
      _exit(3);
    }
    std::uint32_t last = 0;
    for (int i = 0; i < o.samples; ++i) {
      std::int64_t stamp = 0;
      if (udp) {
        if (recv(rx, &stamp, sizeof(stamp), 0) != static_cast<ssize_t>(sizeof(stamp))) _exit(3);
      } else {
        while (shared->seq.load(std::memory_order_acquire) == last) futexCall(&shared->seq, FUTEX_WAIT, last);
        last = shared->seq.load(std::memory_order_acquire);
        stamp = shared->stamp_ns.load(std::memory_order_acquire);
      }
      lat[static_cast<std::size_t>(i)] = static_cast<double>(nowNs() - stamp) * 1e-3;
      shared->taken.store(static_cast<std::uint32_t>(i + 1), std::memory_order_release);
    }
    const bool ok = write(pipe_fd[1], &fifo, sizeof(fifo)) == sizeof(fifo) &&
                    write(pipe_fd[1], lat.data(), lat.size() * sizeof(double)) ==
                        static_cast<ssize_t>(lat.size() * sizeof(double));
    _exit(ok ? 0 : 3);
  }
  close(pipe_fd[1]);
  bool waker_fifo = false;
  try {
    pinTo(r.from_cpu);
    waker_fifo = o.fifo && tryFifo(o.priority);
    std::int64_t next = nowNs() + 20'000'000;  // lets the child reach its first wait
    for (int i = 0; i < o.samples; ++i) {
      sleepUntilNs(next);
      // A sleeper still late from the last wake-up (a stalled CPU) is waited for, not woken twice.
      const std::int64_t give_up = nowNs() + 5'000'000'000;
      while (shared->taken.load(std::memory_order_acquire) < static_cast<std::uint32_t>(i)) {
        if (nowNs() > give_up) throw std::runtime_error("the sleeping process stopped taking wake-ups for 5 s");
        sleepUntilNs(nowNs() + 50'000);
      }
      const std::int64_t t = nowNs();
      if (udp) {
        if (sendto(tx, &t, sizeof(t), 0, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != sizeof(t))
          throw std::runtime_error(std::string("sendto: ") + std::strerror(errno));
      } else {
        shared->stamp_ns.store(t, std::memory_order_release);
        shared->seq.fetch_add(1, std::memory_order_release);
        futexCall(&shared->seq, FUTEX_WAKE, 1);
      }
      next += o.period_us * 1000;
    }
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  sched_param normal{};
  sched_setscheduler(0, SCHED_OTHER, &normal);
  int child_fifo = 0;
  std::vector<double> lat(static_cast<std::size_t>(o.samples));
  // A sleeper that lost a datagram would wait forever: bound the read, then end the child (by its pid).
  const std::int64_t deadline = nowNs() + 10'000'000'000;
  const bool got = r.error.empty() && readAll(pipe_fd[0], &child_fifo, sizeof(child_fifo), deadline) &&
                   readAll(pipe_fd[0], lat.data(), lat.size() * sizeof(double), deadline);
  if (!got) kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(pipe_fd[0]);
  if (udp) {
    close(rx);
    close(tx);
  }
  munmap(shared, sizeof(SharedWake));
  if (!got && r.error.empty())
    r.error = "the sleeping process did not report (a lost datagram or a failed pin; exit status " +
              std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status)) + ")";
  for (double v : lat) r.latency_us.add(v);
  r.fifo = waker_fifo && child_fifo == 1;
}

std::string label(const CaseResult& r) {
  if (r.kind == "timer") return "timer, CPU " + std::to_string(r.to_cpu);
  return r.kind + ", CPU " + std::to_string(r.from_cpu) + " -> " + std::to_string(r.to_cpu) +
         (r.from_cpu == r.to_cpu ? " (one CPU)" : " (across CPUs)");
}

int toolMain(int argc, char** argv) {
  mft::config::CommandLine cli(
      "mft-wakeup",
      "The machine's own wake-up latency (a cyclictest-like probe): timer lateness of a SCHED_FIFO thread on each\n"
      "CPU, and the time one process takes to wake another that sleeps, by a futex in shared memory (a thread\n"
      "hand-off) and by a UDP datagram on loopback (a DDS hop), on one CPU and across CPUs. Each case wakes once\n"
      "per period. The floor under the control chain's realtime latency (docs/loop-benchmark.md).");
  cli.option("samples", "wake-ups per case", "3000");
  cli.option("period-us", "time between wake-ups [us]", "1000");
  cli.option("priority", "SCHED_FIFO priority of the probe's threads (where permitted)", "80");
  cli.flag("no-rt", "do not ask for SCHED_FIFO");
  cli.option("cpus", "the CPUs to probe, as a count from CPU 0 (default: all online)", "");
  cli.flag("json", "print the figures as JSON");
  cli.parse(argc, argv);
  Options o;
  o.samples = static_cast<int>(cli.getInt("samples", 10, 1'000'000));
  o.period_us = cli.getInt("period-us", 50, 1'000'000);
  o.priority = static_cast<int>(cli.getInt("priority", 1, 99));
  o.fifo = !cli.isSet("no-rt");
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  const int cpus = static_cast<int>(cli.get("cpus").empty() ? online : cli.getInt("cpus", 1, online));

  std::vector<CaseResult> cases;
  for (int c = 0; c < cpus; ++c) {
    cases.emplace_back(o.samples);
    cases.back().kind = "timer";
    cases.back().to_cpu = c;
  }
  for (const char* kind : {"futex", "udp"}) {
    for (int to : cpus > 1 ? std::vector<int>{0, 1} : std::vector<int>{0}) {
      cases.emplace_back(o.samples);
      cases.back().kind = kind;
      cases.back().from_cpu = 0;
      cases.back().to_cpu = to;
    }
  }
  const double case_s = static_cast<double>(o.samples) * static_cast<double>(o.period_us) * 1e-6;
  bool failed = false;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::fprintf(stderr, "mft-wakeup: case %zu of %zu: %s, %d wake-ups (about %.0f s left)\n", i + 1, cases.size(),
                 label(cases[i]).c_str(), o.samples, case_s * static_cast<double>(cases.size() - i));
    if (cases[i].kind == "timer")
      timerCase(o, cases[i]);
    else
      pairCase(o, cases[i]);
    failed = failed || !cases[i].error.empty();
  }
  if (cli.isSet("json")) {
    mft::config::JsonWriter w;
    w.beginObject().field("samples", o.samples).field("period_us", o.period_us).key("cases").beginArray();
    for (const auto& r : cases) {
      w.beginObject().field("kind", r.kind).field("from_cpu", r.from_cpu).field("to_cpu", r.to_cpu);
      w.field("sched_fifo", r.fifo).key("latency_us").raw(r.latency_us.json());
      if (!r.error.empty()) w.field("error", r.error);
      w.endObject();
    }
    std::cout << w.endArray().endObject().str() << "\n";
  } else {
    std::printf("%-34s %5s %9s %9s %9s %9s\n", "wake-up latency [us]", "FIFO", "mean", "p50", "p99", "max");
    for (const auto& r : cases) {
      std::printf("%-34s %5s %9.1f %9.1f %9.1f %9.1f%s\n", label(r).c_str(), r.fifo ? "yes" : "no",
                  r.latency_us.mean(), r.latency_us.percentile(0.5), r.latency_us.percentile(0.99),
                  r.latency_us.max(), r.error.empty() ? "" : ("  FAILED: " + r.error).c_str());
    }
  }
  return failed ? 3 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-wakeup", [&] { return toolMain(argc, argv); });
}
