#pragma once
// Progress on stderr (stdout stays clean for --json): one line per stage, percentages on long loops.
#include <chrono>
#include <cstdio>
#include <string>

#include "model/mft_space_fit.hpp"

namespace mft::tools {

class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet), t0_(std::chrono::steady_clock::now()) {}
  void stage(const std::string& what) {
    if (!quiet_) std::fprintf(stderr, "[mft-space %6.2fs] %s\n", seconds(), what.c_str());
  }
  // Prints at every 25 % step of a loop.
  void percent(const std::string& what, int done, int total) {
    if (quiet_ || total <= 0) return;
    const int q = 4 * done / total;
    if (done == total || q != 4 * (done - 1) / total)
      std::fprintf(stderr, "[mft-space %6.2fs]   %s %3d%%\n", seconds(), what.c_str(), 100 * done / total);
  }
  // The pipeline's reports (model::fitMftSpace) through this object.
  model::MftSpaceProgress callbacks() {
    return {[this](const std::string& what) { stage(what); },
            [this](const std::string& what, int done, int total) { percent(what, done, total); }};
  }
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  bool quiet_;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace mft::tools
