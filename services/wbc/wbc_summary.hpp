#pragma once
// mft-wbc's run figures (solve and tick times, non-optimal solves, iterations) gathered tick by tick, and its run
// summary at exit (the JSON the supervisor reads): those figures with the safety stage's counters and the
// tick join's.
#include <cstdint>
#include <string>

#include "services/runtime/deadline_counts.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/tick_join.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft::services {

class WbcFigures {
 public:
  // The tick path: no allocation (LatencyStats preallocates).
  void add(const wbc::WbcDiagnostics& d) {
    solve_us_.add(d.solve_time_us);
    tick_us_.add(d.tick_time_us);
    if (d.status != qp::QpStatus::Optimal) ++non_optimal_;
    if (d.iterations > max_iterations_) max_iterations_ = d.iterations;
  }
  // `deadlines`: RobotState's reader's; `live_changes`: LiveTuning::summaryJson().
  std::string summaryJson(const wbc::WholeBodyController& controller, const TickJoin& join,
                          const DeadlineCounts& deadlines, const std::string& live_changes) const;

 private:
  std::uint64_t non_optimal_ = 0;
  int max_iterations_ = 0;
  LatencyStats solve_us_, tick_us_;
};

}  // namespace mft::services
