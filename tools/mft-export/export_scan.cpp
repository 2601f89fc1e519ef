#include "tools/mft-export/export_scan.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "common/json_writer.hpp"

namespace mft::exporter {

namespace fs = std::filesystem;

namespace {

// The tick bookkeeping of one sample of a ticked topic.
void countTick(LabelInfo& in, double tick) {
  if (in.count == 0) in.first_tick = tick;
  else if (tick == in.last_tick) ++in.tick_repeats;
  else if (tick > in.last_tick + 1) in.tick_gaps += static_cast<std::uint64_t>(tick - in.last_tick - 1);
  in.last_tick = tick;
}

// One CSV row (the file opened with its header on the label's first row); false when it cannot be created.
bool writeRow(std::FILE*& csv, const std::string& csv_dir, const rawlog::LabelSpec& spec, std::int64_t stamp,
              const std::string& cells, std::vector<std::string>* paths) {
  if (!csv) {
    const std::string path = (fs::path(csv_dir) / (spec.label + ".csv")).string();
    csv = std::fopen(path.c_str(), "w");
    if (csv) paths->push_back(path);
    if (!csv) {
      std::fprintf(stderr, "mft-export: cannot write %s: %s\n", path.c_str(), std::strerror(errno));
      return false;
    }
    std::fputs("stamp_ns,time_s", csv);
    for (const auto& c : spec.columns) std::fprintf(csv, ",%s", c.c_str());
    for (const auto& t : spec.text) std::fprintf(csv, ",%s", t.first.c_str());
    std::fputc('\n', csv);
  }
  std::fprintf(csv, "%lld,%.9f", static_cast<long long>(stamp), static_cast<double>(stamp) * 1e-9);
  std::fputs(cells.c_str(), csv);  // integers exact, text quoted
  std::fputc('\n', csv);
  return true;
}

// Closes every CSV; false when one of them failed (a full disk shows only here).
bool closeAll(std::vector<std::FILE*>& files) {
  bool failed = false;
  for (auto& f : files)
    if (f) {
      const bool write_failed = std::ferror(f) != 0;
      failed = (std::fclose(f) != 0) || write_failed || failed;
      f = nullptr;
    }
  return !failed;
}

}  // namespace

Scan scanRecording(rawlog::RawlogReader& reader, const std::string& csv_dir, const std::set<std::string>& only) {
  const auto& md = reader.metadata();
  const auto& specs = rawlog::labels();
  Scan scan;
  scan.info.resize(specs.size());
  std::vector<std::FILE*> csv(specs.size(), nullptr);
  std::vector<std::string> csv_paths;  // removed if writing fails: a cut CSV looks like a short run
  mrpt::obs::CObservation::Ptr obs;
  std::vector<double> values;
  std::string cells;
  while (reader.next(&obs)) {
    const int li = rawlog::labelIndex(obs->sensorLabel);
    if (li < 0 || !rawlog::observationValues(*obs, li, &values) || !rawlog::observationCells(*obs, li, &cells)) {
      ++scan.unknown;
      continue;
    }
    const auto& spec = specs[static_cast<std::size_t>(li)];
    auto& in = scan.info[static_cast<std::size_t>(li)];
    const std::int64_t unix_ns = rawlog::fromMrptTime(obs->timestamp);
    const std::int64_t stamp = unix_ns - md.time_base_unix_ns;
    if (scan.first_unix_ns < 0) scan.first_unix_ns = unix_ns;
    scan.last_unix_ns = std::max(scan.last_unix_ns, unix_ns);
    if (in.count == 0) in.first_ns = stamp;
    in.last_ns = stamp;
    if (rawlog::hasTick(spec.topic) && spec.cls == rawlog::LabelClass::RawDaq) countTick(in, values[0]);
    ++in.count;
    if (!csv_dir.empty() && (only.empty() || only.count(spec.label)) &&
        !writeRow(csv[static_cast<std::size_t>(li)], csv_dir, spec, stamp, cells, &csv_paths)) {
      scan.error = kExitBadInput;
      return scan;
    }
  }
  if (!closeAll(csv)) {
    std::string names;
    for (const auto& p : csv_paths) {
      std::remove(p.c_str());
      names += (names.empty() ? "" : ", ") + fs::path(p).filename().string();
    }
    std::fprintf(stderr, "mft-export: writing the CSV files in %s failed (disk full?): removed the %zu cut files (%s)\n",
                 csv_dir.c_str(), csv_paths.size(), names.c_str());
    scan.error = kExitBadInput;
  }
  return scan;
}

void printSummaryJson(const std::string& file, rawlog::RawlogReader& reader, const Scan& scan, const std::string& csv_dir) {
  const auto& md = reader.metadata();
  const auto& specs = rawlog::labels();
  config::JsonWriter w;
  w.beginObject().field("file", file).field("format", md.format).field("schema_version", md.schema_version);
  w.field("scenario", md.scenario_name).field("mode", md.mode).field("controller", md.controller);
  w.field("created_utc", md.created_utc).field("robot_checksum", md.robot_checksum).field("dds_naming", md.dds_naming);
  w.field("piece", md.piece).field("time_base_unix_ns", md.time_base_unix_ns);
  w.fixedField("first_unix_s", scan.first_unix_ns < 0 ? 0.0 : static_cast<double>(scan.first_unix_ns) * 1e-9, 6);
  w.fixedField("last_unix_s", static_cast<double>(scan.last_unix_ns) * 1e-9, 6).field("file_bytes", reader.fileSize());
  w.field("objects", reader.objects()).field("unknown_objects", scan.unknown).key("labels").beginObject();
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const auto& in = scan.info[i];
    if (!in.count) continue;
    w.key(specs[i].label).beginObject().field("topic", rawlog::topicName(specs[i].topic)).field("count", in.count);
    w.fixedField("first_s", static_cast<double>(in.first_ns) * 1e-9, 9);
    w.fixedField("last_s", static_cast<double>(in.last_ns) * 1e-9, 9).fixedField("first_tick", in.first_tick, 0);
    w.fixedField("last_tick", in.last_tick, 0).field("tick_gaps", in.tick_gaps).field("tick_repeats", in.tick_repeats);
    w.endObject();
  }
  w.endObject().field("end", rawlog::toString(reader.end())).field("end_message", reader.endMessage());
  w.field("csv_dir", csv_dir);
  std::printf("%s\n", w.endObject().str().c_str());
}

void printSummaryText(const std::string& file, rawlog::RawlogReader& reader, const Scan& scan, const std::string& csv_dir) {
  const auto& md = reader.metadata();
  const auto& specs = rawlog::labels();
  std::printf("file       %s (%.2f MB, schema %d, piece %d)\n", file.c_str(), static_cast<double>(reader.fileSize()) / 1e6,
              md.schema_version, md.piece);
  std::printf("run        %s, %s, controller %s, recorded %s, robot %s, DDS names %s\n", md.scenario_name.c_str(),
              md.mode.c_str(), md.controller.c_str(), md.created_utc.c_str(), md.robot_checksum.c_str(),
              md.dds_naming.c_str());
  std::printf("%-16s %-16s %8s %12s %12s %10s %10s %6s\n", "label", "topic", "count", "first [s]", "last [s]",
              "first tick", "last tick", "gaps");
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const auto& in = scan.info[i];
    if (!in.count) continue;
    std::printf("%-16s %-16s %8llu %12.3f %12.3f %10.0f %10.0f %6llu\n", specs[i].label.c_str(),
                rawlog::topicName(specs[i].topic), static_cast<unsigned long long>(in.count),
                static_cast<double>(in.first_ns) * 1e-9, static_cast<double>(in.last_ns) * 1e-9, in.first_tick,
                in.last_tick, static_cast<unsigned long long>(in.tick_gaps));
  }
  std::printf("end        %s\n", reader.endMessage().c_str());
  if (!csv_dir.empty()) std::printf("csv        %s\n", csv_dir.c_str());
}

}  // namespace mft::exporter
