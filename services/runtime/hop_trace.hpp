#pragma once
// Where a lockstep tick's time goes (docs/results/loop-benchmark.md): each service stamps named marks of tick k
// (input received, answer written, ...) with the system-wide monotonic clock, so the stamps of different
// processes compare, and writes them as <dir>/<service>.hops.csv at exit. Off unless the environment variable
// MFT_HOP_TRACE names a directory (scripts/measure-stack.py --hops sets it); then the table is allocated once at
// start-up and the 1 kHz path only stores a number. The first stamp of a tick is kept (a re-sent tick keeps
// its first pass), ticks beyond the capacity are not traced.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <vector>

namespace mft::services {

class HopTrace {
 public:
  HopTrace(const char* service, std::initializer_list<const char*> marks, std::uint64_t capacity = 60000)
      : service_(service), marks_(marks.begin(), marks.end()) {
    const char* dir = std::getenv("MFT_HOP_TRACE");
    if (!dir || !*dir) return;
    dir_ = dir;
    capacity_ = capacity;
    stamps_.assign(capacity_ * marks_.size(), 0);
  }
  ~HopTrace() { write(); }
  HopTrace(const HopTrace&) = delete;
  HopTrace& operator=(const HopTrace&) = delete;

  bool enabled() const { return capacity_ > 0; }
  // Stamps mark `index` (its position in the constructor's list) of `tick`, once.
  void mark(std::size_t index, std::uint64_t tick) {
    if (tick >= capacity_) return;
    std::int64_t& slot = stamps_[tick * marks_.size() + index];
    if (slot == 0)
      slot = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }

 private:
  void write() const {
    if (!enabled()) return;
    const std::string path = dir_ + "/" + service_ + ".hops.csv";
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "%s: cannot write the hop trace %s\n", service_.c_str(), path.c_str());
      return;
    }
    std::fprintf(f, "tick");
    for (const auto& m : marks_) std::fprintf(f, ",%s", m.c_str());
    std::fprintf(f, "\n");
    for (std::uint64_t k = 0; k < capacity_; ++k) {
      const std::int64_t* row = &stamps_[k * marks_.size()];
      bool any = false;
      for (std::size_t i = 0; i < marks_.size(); ++i) any = any || row[i] != 0;
      if (!any) continue;
      std::fprintf(f, "%llu", static_cast<unsigned long long>(k));
      for (std::size_t i = 0; i < marks_.size(); ++i) std::fprintf(f, ",%lld", static_cast<long long>(row[i]));
      std::fprintf(f, "\n");
    }
    std::fclose(f);
  }

  std::string service_;
  std::vector<std::string> marks_;
  std::string dir_;
  std::uint64_t capacity_ = 0;
  std::vector<std::int64_t> stamps_;
};

}  // namespace mft::services
