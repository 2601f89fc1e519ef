#include "services/record/thread_priority.hpp"

#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "services/runtime/polling_udp_transport.hpp"

namespace mft::services {

namespace fs = std::filesystem;

namespace {

// Sets the policy and nice value of every thread of this process but the writer and the main thread
// (housekeeping every 5 ms, and the starvation guard).
void setBackground(Background how, long nice_value, int writer_tid) {
  const int main_tid = static_cast<int>(getpid());
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc/self/task", ec)) {
    const int tid = std::atoi(e.path().filename().c_str());
    if (tid <= 0 || tid == writer_tid || tid == main_tid) continue;
    sched_param none{};
    sched_setscheduler(tid, how == Background::kIdle ? SCHED_IDLE : SCHED_OTHER, &none);
    setpriority(PRIO_PROCESS, static_cast<id_t>(tid), how == Background::kNice ? static_cast<int>(nice_value) : 0);
  }
}

}  // namespace

bool parseBackground(const std::string& text, bool lockstep, Background* out) {
  if (text == "auto") *out = lockstep ? Background::kIdle : Background::kNice;
  else if (text == "idle") *out = Background::kIdle;
  else if (text == "nice") *out = Background::kNice;
  else if (text == "none") *out = Background::kNone;
  else return false;
  return true;
}

BackgroundPolicy::BackgroundPolicy(Background how, long nice_value, double scenario_duration_s, bool polling)
    : how_(how),
      nice_(nice_value),
      // The last half second of the scenario runs at full priority again: when the simulator exits, its
      // participant's goodbye unmatches its writers, and samples of the last ticks still waiting in a niced
      // recorder's socket buffer would be discarded.
      end_ns_(static_cast<std::uint64_t>(std::max(0.0, scenario_duration_s - 0.5) * 1e9)),
      polling_(polling),
      reniced_(how == Background::kNone) {}

void BackgroundPolicy::update(const rawlog::Recorder& recorder, bool topics_flowing) {
  if (!reniced_ && topics_flowing) {
    setBackground(how_, nice_, recorder.writerThreadId());
    reniced_ = true;
  }
  // SCHED_IDLE gets next to nothing while other work keeps every CPU busy (a parallel test run, a sweep): the
  // simulator would then wait on its window until it times out. A receive thread that has not polled for 50 ms
  // falls back to nice, as in realtime, for the rest of the run.
  if (reniced_ && how_ == Background::kIdle && !near_end_ && polling_ &&
      PollingUdpTransport::lastStats().sincePollNs() > 50'000'000) {
    how_ = Background::kNice;
    setBackground(how_, nice_, recorder.writerThreadId());
    ++starvation_fallbacks_;
    std::printf("mft-record: the receive thread was starved at SCHED_IDLE: nice %ld from now on\n", nice_);
    std::fflush(stdout);
  }
  if (reniced_ && how_ != Background::kNone && !near_end_ && recorder.newestStampNs() >= end_ns_) {
    setBackground(Background::kNone, 0, recorder.writerThreadId());
    near_end_ = true;
  }
}

void BackgroundPolicy::restore(const rawlog::Recorder& recorder) {
  if (how_ != Background::kNone) setBackground(Background::kNone, 0, recorder.writerThreadId());
}

std::string threadCpuJson() {
  std::map<std::string, double> by_name;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc/self/task", ec)) {
    std::ifstream f(e.path() / "stat");
    std::string line;
    std::getline(f, line);
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    double utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
      if (i == 14) utime = std::stod(field);
      if (i == 15) stime = std::stod(field);
    }
    by_name[line.substr(open + 1, close - open - 1)] += (utime + stime) / tick;
  }
  config::JsonWriter w;
  w.beginObject();
  double total = 0;
  for (const auto& [name, s] : by_name) {
    w.fixedField(name, s, 3);
    total += s;
  }
  return w.fixedField("total", total, 3).endObject().str();
}

void writePollFields(config::JsonWriter& w, int starvation_fallbacks) {
  const auto& st = PollingUdpTransport::lastStats();
  w.field("receive_polls", st.polls.load()).field("polled_datagrams", st.datagrams.load());
  w.field("max_datagrams_per_poll", st.max_datagrams_per_poll.load()).field("idle_starvation_fallbacks", starvation_fallbacks);
}

}  // namespace mft::services
