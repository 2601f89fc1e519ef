#pragma once
// mft-export's pass over a recording: per label its count, time and tick range, gaps and repeats, and (with a
// CSV folder) one full-precision CSV per label; then the summary (--info, --json) of what the file holds.
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "services/record/rawlog_reader.hpp"

namespace mft::exporter {

constexpr int kExitBadInput = 2;
constexpr int kExitCorrupt = 4;

struct LabelInfo {
  std::uint64_t count = 0;
  std::int64_t first_ns = 0, last_ns = 0;  // simulator time (stamp_ns)
  double first_tick = -1, last_tick = -1;
  std::uint64_t tick_gaps = 0, tick_repeats = 0;
};

struct Scan {
  std::vector<LabelInfo> info;  // per rawlog::labels() entry
  std::uint64_t unknown = 0;
  std::int64_t first_unix_ns = -1, last_unix_ns = 0;
  int error = 0;  // kExitBadInput when a CSV file could not be written (the message is printed)
};

// Reads `reader` to its end; with a non-empty `csv_dir`, writes <csv_dir>/<label>.csv for the labels in `only`
// (every label when empty).
Scan scanRecording(rawlog::RawlogReader& reader, const std::string& csv_dir, const std::set<std::string>& only);

void printSummaryJson(const std::string& file, rawlog::RawlogReader& reader, const Scan& scan, const std::string& csv_dir);
void printSummaryText(const std::string& file, rawlog::RawlogReader& reader, const Scan& scan, const std::string& csv_dir);

}  // namespace mft::exporter
