// mft-replay: plays an mft rawlog back onto the DDS topics with its recorded timing (rate factor, loop,
// start offset, duration, topic filter), or, with --through-wbc, feeds the recorded RobotState and Reference
// through a fresh WholeBodyController built from the recorded configuration and compares its torques with
// the recorded JointCommands (a regression check for controller changes).
#include <cstdio>
#include <memory>

#include "common/tool_io.hpp"
#include "services/runtime/process.hpp"
#include "tools/mft-replay/replay_publish.hpp"
#include "tools/mft-replay/replay_through_wbc.hpp"

using namespace mft;

namespace {

void defineOptions(services::CommandLine& cli) {
  cli.option("file", "the rawlog (or give it as the first argument)");
  cli.option("domain", "DDS domain id to publish on (0..232)", "0");
  cli.option("rate", "playback speed factor (2 = twice as fast)", "1");
  cli.flag("loop", "play again from the start at the end (until interrupted)");
  cli.option("start", "skip this many recorded seconds from the first message", "0");
  cli.option("duration", "play only this many recorded seconds (0 = to the end)", "0");
  cli.option("topics", "comma-separated topics to play (default: all recorded)");
  cli.option("qos", "QoS of the 1 kHz topics: reliable | control (best effort, as in realtime)", "reliable");
  cli.option("wait-subscribers", "wait up to this many seconds for at least one subscriber before playing", "0");
  cli.flag("quiet", "no progress line");
  cli.flag("rt", "try SCHED_FIFO + mlockall for tighter timing (falls back with a warning)");
  cli.flag("through-wbc", "regression check: recorded RobotState + Reference -> fresh WBC -> compare with JointCommand");
  cli.option("tolerance", "--through-wbc: largest accepted |tau - tau_recorded| [N m]", "1e-9");
  cli.option("wbc-config", "--through-wbc: use this wbc.yaml instead of the recorded one (to test a change)");
  cli.flag("ignore-live-changes", "--through-wbc: do not apply the WBC changes recorded from mft-cmd --set "
           "(docs/guide/live-tuning.md); by default each acts from its recorded tick");
  cli.flag("json", "print the result as JSON");
}

}  // namespace

static int toolMain(int argc, char** argv) {
  std::string file = config::CommandLine::takeLeadingArgument(&argc, argv);
  services::CommandLine cli(
      "mft-replay FILE",
      "Play an mft rawlog back onto the DDS topics with its recorded timing, or (--through-wbc) run the recorded\n"
      "states and references through a fresh WBC and compare its torques with the recorded commands.\n"
      "  mft-replay run.rawlog --domain 5 --rate 2 --topics SensorData,GroundTruth\n"
      "  mft-replay run.rawlog --through-wbc [--tolerance 1e-9] [--wbc-config my-wbc.yaml]\n"
      "Exit status: 0 ok (also for a truncated file, with a warning), 1 torques differ, 2 bad input\n"
      "(not an mft rawlog, other schema version, bad option), 4 corrupt file (played up to the damage).");
  defineOptions(cli);
  cli.parse(argc, argv);
  if (file.empty()) file = cli.get("file");
  if (file.empty()) cli.fail("no rawlog given");

  std::unique_ptr<rawlog::RawlogReader> reader;
  try {
    reader = std::make_unique<rawlog::RawlogReader>(file);
  } catch (const rawlog::NotMftRawlog& e) {
    std::fprintf(stderr, "mft-replay: refused: %s\n", e.what());
    return replay::kExitBadInput;
  }
  if (cli.isSet("through-wbc")) return replay::throughWbc(*reader, cli);
  return replay::playback(file, std::move(reader), cli);
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-replay", [&] { return toolMain(argc, argv); });
}
