// mft-export: an mft rawlog to full-precision CSV (one file per label, named columns, %.17g), a summary of
// what a file holds (--info), paper-style figures (--plot: CSV + tools/mft-export/mft-plot.py), or a video of
// the robot as it moved (--video: video.cpp + tools/mft-export/mft-video.py, docs/guide/videos.md).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>

#include "common/tool_io.hpp"
#include "services/record/rawlog_reader.hpp"
#include "services/runtime/process.hpp"
#include "tools/mft-export/export_scan.hpp"
#include "tools/mft-export/video.hpp"

using namespace mft;
using namespace mft::exporter;
namespace fs = std::filesystem;

namespace {

// An output folder must be a folder (or not exist yet, then it is created); refused before anything is read.
void prepareOutputDir(const services::CommandLine& cli, const std::string& option, const std::string& dir) {
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) cli.fail("--" + option + ": " + dir + " exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) cli.fail("--" + option + ": cannot create the folder " + dir + ": " + ec.message());
}

// --labels a,b: the labels to export, each a known one.
std::set<std::string> labelFilter(const services::CommandLine& cli) {
  std::set<std::string> only;
  if (!cli.isSet("labels")) return only;
  std::stringstream ss(cli.get("labels"));
  std::string l;
  while (std::getline(ss, l, ','))
    if (!l.empty()) {
      if (rawlog::labelIndex(l) < 0) cli.fail("--labels: unknown label '" + l + "'");
      only.insert(l);
    }
  return only;
}

// --plot: mft-plot.py draws the figures from the CSV folder.
int drawPlots(const services::CommandLine& cli, const std::string& csv_dir) {
  const std::string script = config::dataFileFor("scripts/mft-plot.py", MFT_PLOT_SCRIPT);
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + csv_dir + "' '" + cli.get("plot") + "'" +
                          (cli.isSet("json") ? " >&2" : "");
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    std::fprintf(stderr, "mft-export: plotting failed (%s)\n", cmd.c_str());
    return 1;
  }
  return 0;
}

// The CSV, --info and --plot modes once the options are checked.
int exportFile(const services::CommandLine& cli, const std::string& file) {
  std::unique_ptr<rawlog::RawlogReader> reader;
  try {
    reader = std::make_unique<rawlog::RawlogReader>(file);
  } catch (const rawlog::NotMftRawlog& e) {
    std::fprintf(stderr, "mft-export: refused: %s\n", e.what());
    return kExitBadInput;
  }
  if (cli.isSet("metadata")) {
    std::fputs(reader->metadata().text.c_str(), stdout);
    return 0;
  }
  std::string csv_dir = cli.get("csv");
  if (cli.isSet("plot")) csv_dir = (fs::path(cli.get("plot")) / "csv").string();
  const std::set<std::string> only = labelFilter(cli);
  if (cli.isSet("plot")) prepareOutputDir(cli, "plot", cli.get("plot"));
  if (!csv_dir.empty()) prepareOutputDir(cli, cli.isSet("plot") ? "plot" : "csv", csv_dir);

  const Scan scan = scanRecording(*reader, csv_dir, only);
  if (scan.error) return scan.error;
  if (cli.isSet("json")) printSummaryJson(file, *reader, scan, csv_dir);
  else printSummaryText(file, *reader, scan, csv_dir);
  if (reader->end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-export: the file is truncated: read up to its last whole record\n");
  if (cli.isSet("plot") && reader->end() != rawlog::RawlogReader::End::Corrupt && drawPlots(cli, csv_dir) != 0) return 1;
  if (reader->end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-export: the file is %s\n", reader->endMessage().c_str());
    return kExitCorrupt;
  }
  return 0;
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
  cli.option("video", "write a video of the run to this .mp4 or .gif file (docs/guide/videos.md)");
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

  return exportFile(cli, file);
}

}  // namespace

int main(int argc, char** argv) {
  return config::guardedMain("mft-export", [&] { return exportMain(argc, argv); });
}
