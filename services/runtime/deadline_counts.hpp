#pragma once
// A chain reader's deadline misses, each explained (topic_io.hpp): those Fast DDS counted while the topic flowed
// (a gap between two samples, or its timer firing early), those outside the stream (before the first sample while
// the stack starts, after the last while it stops), and the gaps over the deadline measured on the reader's own
// clock from the samples' arrivals. In-stream misses without a measured gap are the timer's.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/json_writer.hpp"

namespace mft::services {

struct DeadlineCounts {
  std::uint64_t in_stream = 0, outside_stream = 0, gaps_over_deadline = 0;
  std::vector<std::pair<std::int64_t, std::int64_t>> gap_windows_ns;  // the last gaps [previous, next arrival)
};

// Fields of the summary object being written: <prefix>deadline_misses, <prefix>deadline_misses_outside_stream,
// <prefix>gaps_over_deadline, <prefix>gap_windows_ns (steady_clock, which the simulator's stall probe shares: the
// supervisor tells the machine's gaps from the chain's with them).
inline void writeDeadlineFields(config::JsonWriter& w, const DeadlineCounts& c, const std::string& prefix = "") {
  w.field(prefix + "deadline_misses", c.in_stream).field(prefix + "deadline_misses_outside_stream", c.outside_stream);
  w.field(prefix + "gaps_over_deadline", c.gaps_over_deadline).key(prefix + "gap_windows_ns").beginArray();
  for (const auto& [from, to] : c.gap_windows_ns) w.beginArray().value(from).value(to).endArray();
  w.endArray();
}

}  // namespace mft::services
