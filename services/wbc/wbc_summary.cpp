#include "services/wbc/wbc_summary.hpp"

#include <cstdio>

namespace mft::services {

std::string WbcFigures::summaryJson(const wbc::WholeBodyController& controller, const TickJoin& join,
                                    std::uint64_t deadline_misses, const std::string& live_changes) const {
  const auto& s = controller.safety().counters();
  char buf[900];
  std::snprintf(buf, sizeof buf,
                "{\"service\": \"mft-wbc\", \"variant\": \"%s\", \"ticks\": %llu, \"last_tick\": %llu, "
                "\"non_optimal_solves\": %llu, \"max_iterations\": %d, \"safety_events\": %llu, "
                "\"safety\": {\"nonfinite_input\": %llu, \"model_failure\": %llu, \"solver_failure\": %llu, "
                "\"nonfinite_output\": %llu, \"hold_ticks\": %llu, \"damping_ticks\": %llu}, ",
                wbc::toString(controller.variant()), static_cast<unsigned long long>(join.ticks()),
                static_cast<unsigned long long>(join.lastTick()), static_cast<unsigned long long>(non_optimal_),
                max_iterations_, static_cast<unsigned long long>(s.events),
                static_cast<unsigned long long>(s.nonfinite_input), static_cast<unsigned long long>(s.model_failure),
                static_cast<unsigned long long>(s.solver_failure), static_cast<unsigned long long>(s.nonfinite_output),
                static_cast<unsigned long long>(s.hold_ticks), static_cast<unsigned long long>(s.damping_ticks));
  return std::string(buf) + join.countsJson() + ", \"deadline_misses\": " + std::to_string(deadline_misses) +
         ", \"solve_time_us\": " + solve_us_.json() + ", \"tick_time_us\": " + tick_us_.json() +
         ", \"live_changes\": " + live_changes + "}";
}

}  // namespace mft::services
