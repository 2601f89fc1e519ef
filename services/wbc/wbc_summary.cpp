#include "services/wbc/wbc_summary.hpp"

#include "common/json_writer.hpp"

namespace mft::services {

std::string WbcFigures::summaryJson(const wbc::WholeBodyController& controller, const TickJoin& join,
                                    const DeadlineCounts& deadlines, const std::string& live_changes) const {
  const auto& s = controller.safety().counters();
  config::JsonWriter w;
  w.beginObject().field("service", "mft-wbc").field("variant", wbc::toString(controller.variant()));
  w.field("ticks", join.ticks()).field("last_tick", join.lastTick()).field("non_optimal_solves", non_optimal_);
  w.field("max_iterations", max_iterations_).field("safety_events", s.events).key("safety").beginObject();
  w.field("nonfinite_input", s.nonfinite_input).field("model_failure", s.model_failure);
  w.field("solver_failure", s.solver_failure).field("nonfinite_output", s.nonfinite_output);
  w.field("hold_ticks", s.hold_ticks).field("damping_ticks", s.damping_ticks).endObject();
  join.writeCounts(w);
  writeDeadlineFields(w, deadlines);
  w.key("solve_time_us").raw(solve_us_.json());
  w.key("tick_time_us").raw(tick_us_.json()).key("live_changes").raw(live_changes);
  return w.endObject().str();
}

}  // namespace mft::services
