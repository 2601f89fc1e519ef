#include "services/record/record_run.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "common/json_writer.hpp"
#include "common/strict_yaml.hpp"
#include "model/robot_description.hpp"
#include "services/record/recording_files.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/service_context.hpp"

namespace mft::services {

void declareRecordOptions(CommandLine& cli) {
  ServiceContext::declareOptions(cli);
  cli.option("output", "the rawlog to write (later pieces: <stem>.partNNN<ext>); an existing recording is refused", "", true);
  cli.flag("overwrite", "replace an existing recording at --output (its sidecar and pieces too)");
  cli.option("gzip-level", "0 (stored) .. 9; 1 is fastest and nearly as small (docs/reference/mrpt.md#compression-level)", "1");
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
}

namespace {

// --background, --nice, --reader-qos, --poll-us and --socket-buffer-mb: how the recorder receives.
void readReceiveOptions(const CommandLine& cli, RecordSettings* s) {
  s->nice_value = cli.getInt("nice", 0, 19);
  if (!parseBackground(cli.get("background"), s->lockstep, &s->background))
    cli.fail("--background: expected auto, idle, nice or none, got '" + cli.get("background") + "'");
  if (cli.isSet("rt") || (s->background == Background::kNice && s->nice_value == 0)) s->background = Background::kNone;
  const std::string reader_qos = cli.get("reader-qos");
  if (reader_qos != "profile" && reader_qos != "best_effort") cli.fail("--reader-qos: expected best_effort or profile");
  s->best_effort_readers = reader_qos == "best_effort";
  s->poll_us = cli.getInt("poll-us", 0, 100000);
  s->socket_buffer_bytes = static_cast<std::uint32_t>(cli.getDouble("socket-buffer-mb", 0.1, 256) * 1024 * 1024);
}

// The file options, and where this recorder starts: a new recording (an old one refused or cleared) or the next
// piece of a crashed recorder's.
void readFileOptions(const CommandLine& cli, RecordSettings* s) {
  rawlog::RecorderOptions& opt = s->recorder;
  opt.output = std::filesystem::absolute(cli.get("output")).string();
  opt.gzip_level = static_cast<int>(cli.getInt("gzip-level", 0, 9));
  opt.flush_period_s = cli.getDouble("flush-ms", 1, 100) * 1e-3;
  opt.queue_capacity = static_cast<std::size_t>(cli.getInt("queue", 64, 1 << 24));
  opt.split_mb = cli.getDouble("split-mb", 0, 1e6);
  opt.split_s = cli.getDouble("split-s", 0, 1e7);
  s->linger_s = cli.getDouble("linger-ms", 0, 1000) * 1e-3;
  opt.first_piece = firstPiece(opt.output);
  if (opt.first_piece > 0)
    std::printf("mft-record: restarted after a crash: continuing in %s\n", rawlog::pieceName(opt.output, opt.first_piece).c_str());
  if (opt.first_piece == 0) refuseOrClearOldRecording(opt.output, cli.isSet("overwrite"), cli.isSet("check-config"), cli);
}

}  // namespace

RecordSettings readRecordSettings(const CommandLine& cli) {
  RecordSettings s;
  s.mode = cli.get("mode");
  if (s.mode != "lockstep" && s.mode != "realtime") cli.fail("--mode: expected lockstep or realtime, got '" + s.mode + "'");
  s.lockstep = s.mode == "lockstep";
  const std::string config_dir = cli.get("config-dir");
  model::RobotDescription robot;
  try {
    s.scenario = chain::loadScenario(cli.get("scenario"));
    s.scenario.profiles = chain::activateRunProfiles(config_dir, s.scenario, cli.getAll("profile"));
    robot = model::loadRobotDescription(config_dir + "/robot.yaml");
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (cli.isSet("rt")) tryRealtimeScheduling(80);
  readReceiveOptions(cli, &s);
  readFileOptions(cli, &s);
  s.recorder.metadata.mode = s.mode;
  s.recorder.metadata.domain = static_cast<int>(cli.getInt("domain", 0, kMaxDomainId));
  storeConfiguration(config_dir, cli.get("scenario"), s.scenario, robot, cli, &s.recorder.metadata);
  return s;
}

RecordRun::RecordRun(const CommandLine& cli, const RecordSettings& settings)
    : cli_(cli),
      settings_(settings),
      recorder_(settings.recorder),
      priority_(settings.background, settings.nice_value, settings.scenario.duration_s, settings.poll_us > 0) {
  try {
    recorder_.start();
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  try {
    channel_ = openChannel(cli, settings.lockstep);
    participant_ = std::make_unique<RecordParticipant>(
        settings.recorder.metadata.domain, ServiceContext::profilesFile(cli),
        ReceiveTuning{settings.socket_buffer_bytes, std::chrono::microseconds(settings.poll_us)},
        SecurityOptions{cli.get("secure"), "record"});
    topics_ = std::make_unique<TopicTable>(*participant_, recorder_,
                                           settings.lockstep ? "lockstep_reader" : "control_reader",
                                           settings.best_effort_readers, channel_.get());
    if (settings.lockstep) participant_->enableProgress();
  } catch (const DdsError& e) {
    cli.fail(e.what());
  } catch (const ChainChannelError& e) {
    cli.fail(e.what());
  }
}

std::unique_ptr<ChainChannel> RecordRun::openChannel(const CommandLine& cli, bool lockstep) {
  if (cli.get("chain-shm").empty()) return nullptr;
  if (!lockstep || !cli.get("secure").empty()) cli.fail("--chain-shm: only in lockstep mode, without --secure");
  return std::make_unique<ChainChannel>(cli.get("chain-shm"));
}

void RecordRun::recordUntilShutdown() {
  while (!shutdownRequested()) {
    if (settings_.lockstep) progress_.update(*topics_, *participant_);
    priority_.update(recorder_, topics_->flowing());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// Back to full priority to drain the socket buffers, then keep listening until the topics have been quiet for
// linger-ms (at most 2 s): the supervisor stops every service at once when the simulator ends, and the last tick's
// samples may still be on their way.
void RecordRun::lingerUntilQuiet() {
  priority_.restore(recorder_);
  const auto steady = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
  const auto give_up = steady() + 2'000'000'000LL;
  while (steady() < give_up && steady() - recorder_.lastPushWallNs() < static_cast<std::int64_t>(settings_.linger_s * 1e9))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

int RecordRun::finish() {
  lingerUntilQuiet();
  const std::string cpu_json = threadCpuJson();  // while the DDS threads still exist
  const std::uint64_t channel_lost = topics_->channelLost();
  topics_.reset();  // readers gone: no more pushes
  recorder_.stop();
  const auto s = recorder_.stats();
  std::printf("mft-record: %llu objects, %llu ticks of GroundTruth, %llu dropped, %.2f MB in %zu piece(s): %s\n",
              static_cast<unsigned long long>(s.objects), static_cast<unsigned long long>(s.topics[0].written),
              static_cast<unsigned long long>(s.topics[0].dropped_queue + s.topics[0].tick_gaps),
              static_cast<double>(s.compressed_bytes) / 1e6, s.pieces.size(), s.pieces.empty() ? "" : s.pieces.front().c_str());
  config::JsonWriter w;
  w.beginObject().field("service", "mft-record").field("file", settings_.recorder.output).field("mode", settings_.mode);
  w.key("cpu_s").raw(cpu_json);
  writePollFields(w, priority_.starvationFallbacks());
  w.field("chain_channel", channel_ != nullptr).field("chain_channel_lost", channel_lost);
  recorder_.writeSummary(w);
  writeSummaryFile(cli_.get("summary"), w.endObject().str(), "mft-record");
  return s.error.empty() ? 0 : 1;
}

}  // namespace mft::services
