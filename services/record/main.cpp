// mft-record: subscribes to every topic (topic_table.hpp) and writes an MRPT rawlog (rawlog_format.hpp) from a
// writer thread (recorder.hpp); the DDS callbacks only copy into a bounded queue. Lockstep: it publishes its
// progress for the simulator's flow control. Service contract: READY once the readers exist, exit 0 on
// SIGINT/SIGTERM after draining and closing the file, JSON summary via --summary.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "services/record/recording_files.hpp"
#include "services/record/thread_priority.hpp"
#include "services/record/topic_table.hpp"
#include "services/runtime/service_context.hpp"

using namespace mft;
namespace fs = std::filesystem;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-record",
                            "Records every topic to an MRPT rawlog (observations-only format, standard classes,\n"
                            "metadata comment first, sidecar FILE.yaml). See docs/recording.md.");
  services::ServiceContext::declareOptions(cli);
  cli.option("output", "the rawlog to write (later pieces: <stem>.partNNN<ext>); an existing recording is refused", "", true);
  cli.flag("overwrite", "replace an existing recording at --output (its sidecar and pieces too)");
  cli.option("gzip-level", "0 (stored) .. 9; 1 is fastest and nearly as small (docs/mrpt.md#compression-level)", "1");
  cli.option("flush-ms", "flush period: a crash loses about this much [ms] (at most 100)", "50");
  cli.option("queue", "capacity of the queue between DDS and the writer [messages]", "65536");
  cli.option("split-mb", "start a new piece past this compressed size [MB] (0 = never)", "0");
  cli.option("split-s", "start a new piece every this many simulated seconds (0 = never)", "0");
  cli.option("linger-ms", "on SIGTERM, keep receiving until the topics are quiet this long (at most 2 s)", "200");
  cli.option("background", "how the receiving threads give way to the stack once every topic flows: idle\n"
             "                             (SCHED_IDLE: only CPU nobody wants; lockstep's default, where the recorder\n"
             "                             window stalls the simulator rather than lose a sample), nice (--nice;\n"
             "                             realtime's default, where a starved recorder would lose samples), none", "auto");
  cli.option("nice", "niceness of the receiving threads with --background nice", "10");
  cli.option("reader-qos", "best_effort: best-effort readers on the 1 kHz topics (measured: no losses with the\n"
             "                             large socket buffer, half the cost); profile: the chain's profile (reliable in lockstep)",
             "best_effort");
  cli.option("poll-us", "drain the unicast sockets every this many us instead of being woken per datagram\n"
             "                             (a wake-up costs the sending service ~15-20 us on a VM); 0 = Fast DDS's\n"
             "                             blocking receive", "1000");
  cli.option("socket-buffer-mb", "UDP receive buffer of the recorder's participant [MB] (capped by net.core.rmem_max)", "4");
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  // The contract's options, read as ServiceContext does, but with the recorder's own participant.
  const std::string mode = cli.get("mode");
  if (mode != "lockstep" && mode != "realtime") cli.fail("--mode: expected lockstep or realtime, got '" + mode + "'");
  const bool lockstep = mode == "lockstep";
  const std::string config_dir = cli.get("config-dir");
  model::RobotDescription robot;
  chain::Scenario scenario;
  try {
    scenario = chain::loadScenario(cli.get("scenario"));
    scenario.profiles = chain::activateRunProfiles(config_dir, scenario, cli.getAll("profile"));
    robot = model::loadRobotDescription(config_dir + "/robot.yaml");
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (cli.isSet("rt")) services::tryRealtimeScheduling(80);
  const long nice_value = cli.getInt("nice", 0, 19);
  services::Background background;
  if (!services::parseBackground(cli.get("background"), lockstep, &background))
    cli.fail("--background: expected auto, idle, nice or none, got '" + cli.get("background") + "'");
  if (cli.isSet("rt") || (background == services::Background::kNice && nice_value == 0)) background = services::Background::kNone;
  const std::string reader_qos = cli.get("reader-qos");
  if (reader_qos != "profile" && reader_qos != "best_effort") cli.fail("--reader-qos: expected best_effort or profile");

  rawlog::RecorderOptions opt;
  opt.output = fs::absolute(cli.get("output")).string();
  opt.gzip_level = static_cast<int>(cli.getInt("gzip-level", 0, 9));
  opt.flush_period_s = cli.getDouble("flush-ms", 1, 100) * 1e-3;
  opt.queue_capacity = static_cast<std::size_t>(cli.getInt("queue", 64, 1 << 24));
  opt.split_mb = cli.getDouble("split-mb", 0, 1e6);
  opt.split_s = cli.getDouble("split-s", 0, 1e7);
  const double linger_s = cli.getDouble("linger-ms", 0, 1000) * 1e-3;
  opt.first_piece = services::firstPiece(opt.output);
  if (opt.first_piece > 0)
    std::printf("mft-record: restarted after a crash: continuing in %s\n", rawlog::pieceName(opt.output, opt.first_piece).c_str());
  if (opt.first_piece == 0) services::refuseOrClearOldRecording(opt.output, cli.isSet("overwrite"), cli.isSet("check-config"), cli);
  opt.metadata.mode = mode;
  opt.metadata.domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  services::storeConfiguration(config_dir, cli.get("scenario"), scenario, robot, cli, &opt.metadata);
  if (cli.isSet("check-config")) {
    const std::string problem = services::checkProfilesFile(services::ServiceContext::profilesFile(cli));
    if (!problem.empty()) cli.fail(problem);
    std::printf("mft-record: configuration ok\n");
    return 0;
  }
  fs::create_directories(fs::path(opt.output).parent_path());
  rawlog::Recorder recorder(opt);
  try {
    recorder.start();
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  const long poll_us = cli.getInt("poll-us", 0, 100000);
  std::unique_ptr<services::RecordParticipant> participant;
  std::unique_ptr<services::ChainChannel> channel;  // a lockstep stack's chain channel: the 1 kHz topics from there
  std::unique_ptr<services::TopicTable> topics;
  try {
    if (!cli.get("chain-shm").empty()) {
      if (!lockstep || !cli.get("secure").empty()) cli.fail("--chain-shm: only in lockstep mode, without --secure");
      channel = std::make_unique<services::ChainChannel>(cli.get("chain-shm"));
    }
    participant = std::make_unique<services::RecordParticipant>(
        opt.metadata.domain, services::ServiceContext::profilesFile(cli),
        services::ReceiveTuning{static_cast<std::uint32_t>(cli.getDouble("socket-buffer-mb", 0.1, 256) * 1024 * 1024),
                                std::chrono::microseconds(poll_us)},
        services::SecurityOptions{cli.get("secure"), "record"});
    topics = std::make_unique<services::TopicTable>(*participant, recorder, lockstep ? "lockstep_reader" : "control_reader",
                                                    reader_qos == "best_effort", channel.get());
    if (lockstep) participant->enableProgress();
  } catch (const services::DdsError& e) {
    cli.fail(e.what());
  } catch (const services::ChainChannelError& e) {
    cli.fail(e.what());
  }
  services::ProgressReporter progress;
  services::BackgroundPolicy priority(background, nice_value, scenario.duration_s, poll_us > 0);
  services::announceReady("mft-record");
  while (!services::shutdownRequested()) {
    if (lockstep) progress.update(*topics, *participant);
    priority.update(recorder, topics->flowing());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // Back to full priority to drain the socket buffers, then keep listening until the topics have been quiet for
  // linger-ms (at most 2 s): the supervisor stops every service at once when the simulator ends, and the last
  // tick's samples may still be on their way.
  priority.restore(recorder);
  const auto steady = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
  const auto give_up = steady() + 2'000'000'000LL;
  while (steady() < give_up && steady() - recorder.lastPushWallNs() < static_cast<std::int64_t>(linger_s * 1e9))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::string cpu_json = services::threadCpuJson();  // while the DDS threads still exist
  const std::uint64_t channel_lost = topics->channelLost();
  topics.reset();  // readers gone: no more pushes
  recorder.stop();
  const auto s = recorder.stats();
  std::printf("mft-record: %llu objects, %llu ticks of GroundTruth, %llu dropped, %.2f MB in %zu piece(s): %s\n",
              static_cast<unsigned long long>(s.objects), static_cast<unsigned long long>(s.topics[0].written),
              static_cast<unsigned long long>(s.topics[0].dropped_queue + s.topics[0].tick_gaps),
              static_cast<double>(s.compressed_bytes) / 1e6, s.pieces.size(), s.pieces.empty() ? "" : s.pieces.front().c_str());
  config::JsonWriter w;
  w.beginObject().field("service", "mft-record").field("file", opt.output).field("mode", mode).key("cpu_s").raw(cpu_json);
  services::writePollFields(w, priority.starvationFallbacks());
  w.field("chain_channel", channel != nullptr).field("chain_channel_lost", channel_lost);
  recorder.writeSummary(w);
  services::writeSummaryFile(cli.get("summary"), w.endObject().str(), "mft-record");
  return s.error.empty() ? 0 : 1;
}
// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-record", [&] { return toolMain(argc, argv); });
}
