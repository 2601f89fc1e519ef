// mft-export: an mft rawlog to full-precision CSV (one file per label, named columns, %.17g), a summary of
// what a file holds (--info), paper-style figures (--plot: CSV + tools/mft-export/mft-plot.py), or a video of
// the robot as it moved (--video: video.cpp + tools/mft-export/mft-video.py, docs/videos.md).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

#include "common/tool_io.hpp"
#include "services/record/rawlog_reader.hpp"
#include "services/runtime/process.hpp"
#include "tools/mft-export/video.hpp"

using namespace mft;
namespace fs = std::filesystem;

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitCorrupt = 4;


struct LabelInfo {
  std::uint64_t count = 0;
  std::int64_t first_ns = 0, last_ns = 0;  // simulator time (stamp_ns)
  double first_tick = -1, last_tick = -1;
  std::uint64_t tick_gaps = 0, tick_repeats = 0;
  std::FILE* csv = nullptr;
};

// An output folder must be a folder (or not exist yet, then it is created); refused before anything is read.
void prepareOutputDir(const services::CommandLine& cli, const std::string& option, const std::string& dir) {
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) cli.fail("--" + option + ": " + dir + " exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) cli.fail("--" + option + ": cannot create the folder " + dir + ": " + ec.message());
}

int exportMain(int argc, char** argv) {
  std::string file = config::CommandLine::takeLeadingArgument(&argc, argv);
  services::CommandLine cli(
      "mft-export FILE",
      "Export an mft rawlog: --csv DIR writes <DIR>/<label>.csv (stamp_ns, time_s, then the named channels at\n"
      "full precision); --info summarises the file (labels, counts, ticks, how it ends); --plot DIR also draws\n"
      "paper-style figures (floating base, hip angles, contact forces) with python3-matplotlib; --video OUT.mp4\n"
      "(or .gif) draws the robot as it moved (legs through the five-bar kinematics, ground, contact forces, the\n"
      "push, legs green inside / red outside the MFT preferable space), in real time unless --speed, with ffmpeg.\n"
      "Exit status: 0 ok (also for a truncated file, with a warning), 2 not an mft rawlog / other schema /\n"
      "bad option / output not writable / ffmpeg missing, 4 corrupt (exported up to the damage), 130 interrupted.");
  cli.option("file", "the rawlog (or give it as the first argument)");
  cli.option("csv", "write one CSV per label into this folder");
  cli.option("labels", "comma-separated labels to export (default: all)");
  cli.flag("info", "print what the file holds");
  cli.option("plot", "write CSV into DIR/csv and figures (PNG) into DIR");
  cli.flag("metadata", "print the metadata comment (YAML) and exit");
  cli.flag("json", "print the summary as JSON");
  cli.option("video", "write a video of the run to this .mp4 or .gif file (docs/videos.md)");
  cli.option("beside", "with --video: a second rawlog drawn beside the first, on the same clock (e.g. the other "
                       "controller's run of the same push)");
  cli.option("speed", "with --video: simulated seconds per video second (default 1: real time; 0.25 = slow motion)");
  cli.option("from", "with --video: first simulated time drawn [s] (default 0)");
  cli.option("to", "with --video: last simulated time drawn [s] (default: the end of the recording)");
  cli.option("fps", "with --video: frames per second of the video (default 30 for .mp4, 15 for .gif)");
  cli.flag("overwrite", "with --video: replace an existing output file");
  cli.option("frame-log", "with --video: also write, per frame, the drawn points and the world-to-pixel mapping "
                          "as JSON lines to this file (tests)");
  cli.parse(argc, argv);
  if (file.empty()) file = cli.get("file");
  if (file.empty()) cli.fail("no rawlog given");
  if (cli.isSet("video")) return video::videoMain(cli, file);
  for (const char* video_only : {"beside", "speed", "from", "to", "fps", "overwrite", "frame-log"})
    if (cli.isSet(video_only)) cli.fail(std::string("--") + video_only + " only applies to --video");
  if (!cli.isSet("csv") && !cli.isSet("info") && !cli.isSet("plot") && !cli.isSet("metadata"))
    cli.fail("nothing to do: give --csv DIR, --plot DIR, --video OUT, --info or --metadata");

  std::unique_ptr<rawlog::RawlogReader> reader;
  try {
    reader = std::make_unique<rawlog::RawlogReader>(file);
  } catch (const rawlog::NotMftRawlog& e) {
    std::fprintf(stderr, "mft-export: refused: %s\n", e.what());
    return kExitBadInput;
  }
  const auto& md = reader->metadata();
  if (cli.isSet("metadata")) {
    std::fputs(md.text.c_str(), stdout);
    return 0;
  }
  std::string csv_dir = cli.get("csv");
  if (cli.isSet("plot")) csv_dir = (fs::path(cli.get("plot")) / "csv").string();
  std::set<std::string> only;
  if (cli.isSet("labels")) {
    std::stringstream ss(cli.get("labels"));
    std::string l;
    while (std::getline(ss, l, ','))
      if (!l.empty()) {
        if (rawlog::labelIndex(l) < 0) cli.fail("--labels: unknown label '" + l + "'");
        only.insert(l);
      }
  }
  if (cli.isSet("plot")) prepareOutputDir(cli, "plot", cli.get("plot"));
  if (!csv_dir.empty()) prepareOutputDir(cli, cli.isSet("plot") ? "plot" : "csv", csv_dir);

  const auto& specs = rawlog::labels();
  std::vector<LabelInfo> info(specs.size());
  std::uint64_t unknown = 0;
  mrpt::obs::CObservation::Ptr obs;
  std::vector<double> values;
  std::string cells;
  std::int64_t last_unix_ns = 0, first_unix_ns = -1;
  std::vector<std::string> csv_paths;  // removed if writing fails: a cut CSV looks like a short run
  while (reader->next(&obs)) {
    const int li = rawlog::labelIndex(obs->sensorLabel);
    if (li < 0 || !rawlog::observationValues(*obs, li, &values) || !rawlog::observationCells(*obs, li, &cells)) {
      ++unknown;
      continue;
    }
    const auto& spec = specs[static_cast<std::size_t>(li)];
    auto& in = info[static_cast<std::size_t>(li)];
    const std::int64_t unix_ns = rawlog::fromMrptTime(obs->timestamp);
    const std::int64_t stamp = unix_ns - md.time_base_unix_ns;
    if (first_unix_ns < 0) first_unix_ns = unix_ns;
    last_unix_ns = std::max(last_unix_ns, unix_ns);
    if (in.count == 0) in.first_ns = stamp;
    in.last_ns = stamp;
    if (rawlog::hasTick(spec.topic) && spec.cls == rawlog::LabelClass::RawDaq) {
      const double tick = values[0];
      if (in.count == 0) in.first_tick = tick;
      else if (tick == in.last_tick) ++in.tick_repeats;
      else if (tick > in.last_tick + 1) in.tick_gaps += static_cast<std::uint64_t>(tick - in.last_tick - 1);
      in.last_tick = tick;
    }
    ++in.count;
    if (!csv_dir.empty() && (only.empty() || only.count(spec.label))) {
      if (!in.csv) {
        const std::string path = (fs::path(csv_dir) / (spec.label + ".csv")).string();
        in.csv = std::fopen(path.c_str(), "w");
        if (in.csv) csv_paths.push_back(path);
        if (!in.csv) {
          std::fprintf(stderr, "mft-export: cannot write %s: %s\n", path.c_str(), std::strerror(errno));
          return kExitBadInput;
        }
        std::fputs("stamp_ns,time_s", in.csv);
        for (const auto& c : spec.columns) std::fprintf(in.csv, ",%s", c.c_str());
        for (const auto& t : spec.text) std::fprintf(in.csv, ",%s", t.first.c_str());
        std::fputc('\n', in.csv);
      }
      std::fprintf(in.csv, "%lld,%.9f", static_cast<long long>(stamp), static_cast<double>(stamp) * 1e-9);
      std::fputs(cells.c_str(), in.csv);  // integers exact, text quoted
      std::fputc('\n', in.csv);
    }
  }
  bool csv_write_failed = false;  // a full disk shows only here: say so rather than leave short CSV files
  for (auto& in : info)
    if (in.csv) {
      const bool failed = std::ferror(in.csv) != 0;
      csv_write_failed = (std::fclose(in.csv) != 0) || failed || csv_write_failed;
    }
  if (csv_write_failed) {
    std::string names;
    for (const auto& p : csv_paths) {
      std::remove(p.c_str());
      names += (names.empty() ? "" : ", ") + fs::path(p).filename().string();
    }
    std::fprintf(stderr, "mft-export: writing the CSV files in %s failed (disk full?): removed the %zu cut files (%s)\n",
                 csv_dir.c_str(), csv_paths.size(), names.c_str());
    return kExitBadInput;
  }

  const bool json = cli.isSet("json");
  if (json) {
    config::JsonWriter w;
    w.beginObject().field("file", file).field("format", md.format).field("schema_version", md.schema_version);
    w.field("scenario", md.scenario_name).field("mode", md.mode).field("controller", md.controller);
    w.field("created_utc", md.created_utc).field("robot_checksum", md.robot_checksum).field("dds_naming", md.dds_naming);
    w.field("piece", md.piece).field("time_base_unix_ns", md.time_base_unix_ns);
    w.fixedField("first_unix_s", first_unix_ns < 0 ? 0.0 : static_cast<double>(first_unix_ns) * 1e-9, 6);
    w.fixedField("last_unix_s", static_cast<double>(last_unix_ns) * 1e-9, 6).field("file_bytes", reader->fileSize());
    w.field("objects", reader->objects()).field("unknown_objects", unknown).key("labels").beginObject();
    for (std::size_t i = 0; i < specs.size(); ++i) {
      const auto& in = info[i];
      if (!in.count) continue;
      w.key(specs[i].label).beginObject().field("topic", rawlog::topicName(specs[i].topic)).field("count", in.count);
      w.fixedField("first_s", static_cast<double>(in.first_ns) * 1e-9, 9);
      w.fixedField("last_s", static_cast<double>(in.last_ns) * 1e-9, 9).fixedField("first_tick", in.first_tick, 0);
      w.fixedField("last_tick", in.last_tick, 0).field("tick_gaps", in.tick_gaps).field("tick_repeats", in.tick_repeats);
      w.endObject();
    }
    w.endObject().field("end", rawlog::toString(reader->end())).field("end_message", reader->endMessage());
    w.field("csv_dir", csv_dir);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("file       %s (%.2f MB, schema %d, piece %d)\n", file.c_str(), static_cast<double>(reader->fileSize()) / 1e6,
                md.schema_version, md.piece);
    std::printf("run        %s, %s, controller %s, recorded %s, robot %s, DDS names %s\n", md.scenario_name.c_str(),
                md.mode.c_str(), md.controller.c_str(), md.created_utc.c_str(), md.robot_checksum.c_str(),
                md.dds_naming.c_str());
    std::printf("%-16s %-16s %8s %12s %12s %10s %10s %6s\n", "label", "topic", "count", "first [s]", "last [s]",
                "first tick", "last tick", "gaps");
    for (std::size_t i = 0; i < specs.size(); ++i) {
      const auto& in = info[i];
      if (!in.count) continue;
      std::printf("%-16s %-16s %8llu %12.3f %12.3f %10.0f %10.0f %6llu\n", specs[i].label.c_str(),
                  rawlog::topicName(specs[i].topic), static_cast<unsigned long long>(in.count),
                  static_cast<double>(in.first_ns) * 1e-9, static_cast<double>(in.last_ns) * 1e-9, in.first_tick,
                  in.last_tick, static_cast<unsigned long long>(in.tick_gaps));
    }
    std::printf("end        %s\n", reader->endMessage().c_str());
    if (!csv_dir.empty()) std::printf("csv        %s\n", csv_dir.c_str());
  }
  if (reader->end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-export: the file is truncated: read up to its last whole record\n");
  if (cli.isSet("plot") && reader->end() != rawlog::RawlogReader::End::Corrupt) {
    const std::string script = config::dataFileFor("scripts/mft-plot.py", MFT_PLOT_SCRIPT);
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + csv_dir + "' '" + cli.get("plot") + "'" +
                            (json ? " >&2" : "");
    const int rc = std::system(cmd.c_str());
    if (rc != 0) {
      std::fprintf(stderr, "mft-export: plotting failed (%s)\n", cmd.c_str());
      return 1;
    }
  }
  if (reader->end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-export: the file is %s\n", reader->endMessage().c_str());
    return kExitCorrupt;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return config::guardedMain("mft-export", [&] { return exportMain(argc, argv); });
}
