// mft-record: subscribes to every topic and writes an MRPT rawlog (services/record/rawlog_format.hpp) from a
// writer thread; the DDS callbacks only copy into a bounded queue. Lockstep: reliable readers (every tick
// arrives); realtime: the control profiles the writers offer. Service contract: READY once the readers
// exist, exit 0 on SIGINT/SIGTERM after draining and closing the file, JSON summary via --summary.
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <map>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <type_traits>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include "idl/msg_pubsub.hpp"
#include "model/config/profiles.hpp"
#include "model/config/strict_yaml.hpp"
#include "services/runtime/polling_udp_transport.hpp"
#include "services/record/recorder.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_names.hpp"
#include "chain/scenario.hpp"
#include "services/runtime/service_context.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;
namespace fs = std::filesystem;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

void writeSummary(const std::string& path, const std::string& json) {
  services::writeSummaryFile(path, json, "mft-record");
}

// CPU seconds used so far by this process's threads, summed by thread name (the DDS receive threads versus
// the writer): what the recorder costs the machine, independent of how busy the machine is.
std::string threadCpuJson() {
  std::map<std::string, double> by_name;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc/self/task", ec)) {
    std::ifstream f(e.path() / "stat");
    std::string line;
    std::getline(f, line);
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    double utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
      if (i == 14) utime = std::stod(field);
      if (i == 15) stime = std::stod(field);
    }
    by_name[line.substr(open + 1, close - open - 1)] += (utime + stime) / tick;
  }
  std::string j = "{";
  double total = 0;
  for (const auto& [name, s] : by_name) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s\"%s\": %.3f", j.size() > 1 ? ", " : "", name.c_str(), s);
    j += buf;
    total += s;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s\"total\": %.3f}", j.size() > 1 ? ", " : "", total);
  return j + buf;
}

// Sets the nice value of every thread of this process but `except_tid` (Linux: nice is per thread).
// How the recorder's DDS-side threads (all but the writer) give way to the stack once the topics flow.
enum class Background { kNone, kNice, kIdle };

// The writer thread and the main thread (housekeeping every 5 ms, and the starvation guard below) keep theirs.
void setBackground(Background how, long nice_value, int writer_tid) {
  const int main_tid = static_cast<int>(getpid());
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc/self/task", ec)) {
    const int tid = std::atoi(e.path().filename().c_str());
    if (tid <= 0 || tid == writer_tid || tid == main_tid) continue;
    sched_param none{};
    sched_setscheduler(tid, how == Background::kIdle ? SCHED_IDLE : SCHED_OTHER, &none);
    setpriority(PRIO_PROCESS, static_cast<id_t>(tid), how == Background::kNice ? static_cast<int>(nice_value) : 0);
  }
}

bool pidAlive(long pid) { return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

// After a crash the supervisor restarts the recorder with the same --output: continue in the next free piece
// instead of overwriting what the crashed one wrote. A restart is recognised by the sidecar of the output:
// still "recording", written by a recorder that is gone, under the same parent (the supervisor).
int firstPiece(const std::string& output) {
  const std::string sidecar = rawlog::sidecarName(output);
  if (!fs::exists(sidecar)) return 0;
  try {
    const YAML::Node n = YAML::LoadFile(sidecar)["recording"];
    if (!n || n["status"].as<std::string>("") != "recording") return 0;
    if (n["parent_pid"].as<long>(0) != static_cast<long>(getppid()) || pidAlive(n["recorder_pid"].as<long>(0))) return 0;
  } catch (const YAML::Exception&) {
    return 0;
  }
  int piece = 1;
  while (fs::exists(rawlog::pieceName(output, piece))) ++piece;
  return piece;
}

// A recording is never replaced silently: an existing --output (or its sidecar) is refused unless --overwrite,
// which removes the old sidecar and pieces too, so that nothing of the old recording is read with the new one.
// (A recorder restarted by the supervisor continues in a new piece instead: firstPiece() > 0.)
void refuseOrClearOldRecording(const std::string& output, bool overwrite, bool check_only,
                               const services::CommandLine& cli) {
  const std::string sidecar = rawlog::sidecarName(output);
  std::error_code ec;
  const bool exists = fs::exists(output, ec) || fs::exists(sidecar, ec);
  if (!exists) return;
  if (!overwrite)
    cli.fail(output + " already exists: refusing to replace a recording (--overwrite replaces it)");
  if (fs::is_directory(output, ec)) cli.fail("--output " + output + " is a directory");
  if (check_only) return;  // --check-config changes nothing
  fs::remove(output, ec);
  fs::remove(sidecar, ec);
  for (int piece = 1; fs::exists(rawlog::pieceName(output, piece), ec); ++piece) fs::remove(rawlog::pieceName(output, piece), ec);
}

namespace dds = eprosima::fastdds::dds;

// What the polling receive path did (all zero with --poll-us 0).
std::string pollJson(int starvation_fallbacks) {
  const auto& st = services::PollingUdpTransport::lastStats();
  return "\"receive_polls\": " + std::to_string(st.polls.load()) + ", \"polled_datagrams\": " +
         std::to_string(st.datagrams.load()) + ", \"max_datagrams_per_poll\": " + std::to_string(st.max_datagrams_per_poll.load()) +
         ", \"idle_starvation_fallbacks\": " + std::to_string(starvation_fallbacks);
}

// The recorder's own participant: the project's "mft_participant" profile with larger socket buffers. It
// takes in every topic of a 1 kHz stack (~10k messages/s counting the services' re-sends) on one receive
// thread; with the kernel's default 208 KB buffer, a few ms without CPU on a loaded machine overflowed it,
// and a lost sample of a KEEP_LAST 64 writer is gone for good (measured: ~1 % of ticks).
class RecorderParticipant {
 public:
  RecorderParticipant(int domain, const std::string& profiles_file, const services::ReceiveTuning& tuning,
                      const services::SecurityOptions& security) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    if (factory->load_XML_profiles_file(profiles_file) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      throw services::DdsError("the DDS profile file " + profiles_file + " could not be loaded");
    dds::DomainParticipantQos qos;
    if (factory->get_participant_qos_from_profile("mft_participant", qos) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      throw services::DdsError(profiles_file + ": no participant profile 'mft_participant'");
    qos.name("mft-record");
    services::applyReceiveTuning(tuning, &qos);
    services::applySecurity(security, &qos);
    participant_ = factory->create_participant(domain, qos);
    if (!participant_) throw services::DdsError("cannot create a DDS participant on domain " + std::to_string(domain));
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (!subscriber_) throw services::DdsError("cannot create the DDS subscriber");
  }
  ~RecorderParticipant() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  dds::DomainParticipant* get() const { return participant_; }
  dds::Subscriber* subscriber() const { return subscriber_; }

  // Lockstep flow control: tells the simulator how far the recorder has read.
  void enableProgress() {
    dds::TypeSupport type(new msg::RecorderProgressPubSubType());
    type.register_type(participant_);
    auto* topic = participant_->create_topic(services::ddsTopicName("RecorderProgress"), type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    if (!topic || !publisher_) throw services::DdsError("cannot create the RecorderProgress topic");
    progress_writer_ = publisher_->create_datawriter_with_profile(topic, "lockstep_writer");  // best effort: re-sent every 50 ms at worst
    if (!progress_writer_) throw services::DdsError("cannot create a writer on RecorderProgress (permissions?)");
  }
  void publishProgress(std::uint64_t tick, std::uint64_t all_topics_tick, std::uint64_t received) {
    if (!progress_writer_) return;
    progress_.tick(tick);
    progress_.all_topics_tick(all_topics_tick);
    progress_.received(received);
    progress_writer_->write(&progress_);
  }

 private:
  dds::DomainParticipant* participant_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::DataWriter* progress_writer_ = nullptr;
  msg::RecorderProgress progress_;
};

template <class M, class = void>
struct HasTick : std::false_type {};
template <class M>
struct HasTick<M, std::void_t<decltype(std::declval<const M&>().tick())>> : std::true_type {};

// One topic into the recorder: the DDS receive thread copies each sample into the recorder's queue.
template <class Msg, class PubSubType>
class Subscription : public dds::DataReaderListener {
 public:
  Subscription(RecorderParticipant& p, const std::string& topic_name, const std::string& profile, rawlog::Recorder& rec,
               bool best_effort = false)
      : subscriber_(p.subscriber()), recorder_(rec) {
    dds::TypeSupport type(new PubSubType());
    type.register_type(p.get());
    topic_ = p.get()->create_topic(services::ddsTopicName(topic_name), type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (!topic_) throw services::DdsError("cannot create the topic " + topic_name);
    dds::DataReaderQos qos;
    if (subscriber_->get_datareader_qos_from_profile(profile, qos) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      throw services::DdsError("no reader profile " + profile);
    if (best_effort) qos.reliability().kind = dds::BEST_EFFORT_RELIABILITY_QOS;  // matches any writer, no acks
    reader_ = subscriber_->create_datareader(topic_, qos, this);
    if (!reader_) throw services::DdsError("cannot create a reader on " + topic_name + " with profile " + profile);
  }
  ~Subscription() override { subscriber_->delete_datareader(reader_); }
  void on_data_available(dds::DataReader* reader) override {
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      if (info.valid_data) {
        recorder_.push(rawlog::Message(sample_));
        received_.fetch_add(1, std::memory_order_relaxed);
        if constexpr (HasTick<Msg>::value)
          if (sample_.tick() > last_tick_.load(std::memory_order_relaxed)) last_tick_.store(sample_.tick(), std::memory_order_relaxed);
      }
  }
  std::uint64_t received() const { return received_.load(std::memory_order_relaxed); }
  std::uint64_t lastTick() const { return last_tick_.load(std::memory_order_relaxed); }

 private:
  dds::Subscriber* subscriber_;
  rawlog::Recorder& recorder_;
  dds::Topic* topic_ = nullptr;
  dds::DataReader* reader_ = nullptr;
  Msg sample_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> last_tick_{0};
};

}  // namespace

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
  // The contract's options, read as ServiceContext does, but with the recorder's own participant (above).
  const std::string mode = cli.get("mode");
  if (mode != "lockstep" && mode != "realtime") cli.fail("--mode: expected lockstep or realtime, got '" + mode + "'");
  const bool lockstep = mode == "lockstep";
  const int domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  const std::string config_dir = cli.get("config-dir");
  auto config_file = [&](const std::string& name) { return config_dir + "/" + name; };
  model::RobotDescription robot;
  chain::Scenario scenario;
  try {
    scenario = chain::loadScenario(cli.get("scenario"));
    scenario.profiles = chain::activateRunProfiles(config_dir, scenario, cli.getAll("profile"));
    robot = model::loadRobotDescription(config_file("robot.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (cli.isSet("rt")) services::tryRealtimeScheduling(80);
  const long nice_value = cli.getInt("nice", 0, 19);
  const std::string background_name = cli.get("background");
  Background background = lockstep ? Background::kIdle : Background::kNice;
  if (background_name == "idle") background = Background::kIdle;
  else if (background_name == "nice") background = Background::kNice;
  else if (background_name == "none") background = Background::kNone;
  else if (background_name != "auto") cli.fail("--background: expected auto, idle, nice or none, got '" + background_name + "'");
  if (cli.isSet("rt") || (background == Background::kNice && nice_value == 0)) background = Background::kNone;

  rawlog::RecorderOptions opt;
  opt.output = fs::absolute(cli.get("output")).string();
  opt.gzip_level = static_cast<int>(cli.getInt("gzip-level", 0, 9));
  opt.flush_period_s = cli.getDouble("flush-ms", 1, 100) * 1e-3;
  opt.queue_capacity = static_cast<std::size_t>(cli.getInt("queue", 64, 1 << 24));
  opt.split_mb = cli.getDouble("split-mb", 0, 1e6);
  opt.split_s = cli.getDouble("split-s", 0, 1e7);
  const double linger_s = cli.getDouble("linger-ms", 0, 1000) * 1e-3;
  opt.first_piece = firstPiece(opt.output);
  if (opt.first_piece > 0)
    std::printf("mft-record: restarted after a crash: continuing in %s\n", rawlog::pieceName(opt.output, opt.first_piece).c_str());
  if (opt.first_piece == 0) refuseOrClearOldRecording(opt.output, cli.isSet("overwrite"), cli.isSet("check-config"), cli);

  // The effective configuration of every service: the files of --config-dir they read (with the profiles in
  // force applied, so what is stored is what ran), the scenario and its terrain, so a recording can rebuild
  // its controller (mft-replay --through-wbc). The profiles are named, and their files stored verbatim.
  auto& md = opt.metadata;
  md.created_utc = utcNow();
  md.mode = mode;
  md.domain = domain;
  md.scenario_file = fs::absolute(cli.get("scenario")).string();
  md.scenario_name = scenario.name;
  md.controller = scenario.controller;
  md.robot_checksum = model::checksumHex(robot.checksum);
  md.profiles = scenario.profiles;
  md.dds_naming = services::kDdsNaming;
  const auto& profiles = config::activeProfiles();
  for (const char* f : {"robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml"}) {
    if (!fs::exists(config_file(f))) cli.fail("missing configuration " + config_file(f));
    try {
      md.config[f] = profiles.applyToText(config::profileStemOf(f), readFile(config_file(f)), config_file(f));
    } catch (const config::ConfigError& e) {
      cli.fail(e.what());
    }
  }
  for (const auto& name : md.profiles) md.config["profiles/" + name + ".yaml"] = readFile(config_file("profiles/" + name + ".yaml"));
  md.config["scenario"] = readFile(cli.get("scenario"));
  const std::string terrain = "terrain/" + scenario.terrain + ".yaml";
  if (fs::exists(config_file(terrain))) md.config[terrain] = readFile(config_file(terrain));

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

  std::unique_ptr<RecorderParticipant> participant;
  try {
    participant = std::make_unique<RecorderParticipant>(
        domain, services::ServiceContext::profilesFile(cli),
        services::ReceiveTuning{static_cast<std::uint32_t>(cli.getDouble("socket-buffer-mb", 0.1, 256) * 1024 * 1024),
                                std::chrono::microseconds(cli.getInt("poll-us", 0, 100000))},
        services::SecurityOptions{cli.get("secure"), "record"});
  } catch (const services::DdsError& e) {
    cli.fail(e.what());
  }
  std::string cpu_json;
  int starvation_fallbacks = 0;
  {
    // The writers of the 1 kHz chain offer best effort in both modes (lockstep recovers a lost sample by
    // re-sending the tick, docs/recording.md); a reader asking for more would not match. Losses show as
    // tick gaps; re-sent ticks as repeats.
    const std::string reader_qos = cli.get("reader-qos");
    if (reader_qos != "profile" && reader_qos != "best_effort") cli.fail("--reader-qos: expected best_effort or profile");
    const std::string chain = lockstep ? "lockstep_reader" : "control_reader";
    const bool be = reader_qos == "best_effort";
    auto& p = *participant;
    Subscription<msg::GroundTruth, msg::GroundTruthPubSubType> r0(p, "GroundTruth", chain, recorder, be);
    Subscription<msg::SensorData, msg::SensorDataPubSubType> r1(p, "SensorData", chain, recorder, be);
    Subscription<msg::RobotState, msg::RobotStatePubSubType> r2(p, "RobotState", chain, recorder, be);
    Subscription<msg::Reference, msg::ReferencePubSubType> r3(p, "Reference", chain, recorder, be);
    Subscription<msg::JointCommand, msg::JointCommandPubSubType> r4(p, "JointCommand", chain, recorder, be);
    Subscription<msg::WbcDiagnostics, msg::WbcDiagnosticsPubSubType> r5(p, "WbcDiagnostics", chain, recorder, be);
    Subscription<msg::OperatorCommand, msg::OperatorCommandPubSubType> r6(p, "OperatorCommand", "event_reader", recorder);
    Subscription<msg::Disturbance, msg::DisturbancePubSubType> r7(p, "Disturbance", "event_reader", recorder);
    // Not recorded: CommandVerdict (the stack's answer to mft-cmd). Its reason is text, which rawlog schema 1's
    // numeric channels cannot hold, and a new topic would change the schema that older recordings and tools
    // share; the commands themselves are recorded above, and each verdict (with the tick a command was applied
    // at) is in the planner's and simulator's logs and summaries (docs/operator-commands.md).
    if (lockstep) {
      try {
        p.enableProgress();
      } catch (const services::DdsError& e) {
        cli.fail(e.what());
      }
    }
    // Lockstep: publish how far the recorder has read its socket (the simulator waits when this falls more
    // than its --recorder-window behind). From this 5 ms loop, not per sample: no cost per tick.
    std::uint64_t progress_sent = 0, progress_all_sent = 0;
    int progress_idle_loops = 0;
    auto flowing = [&] { return r0.received() && r1.received() && r2.received() && r3.received() && r4.received() && r5.received(); };
    auto publishProgress = [&] {
      // Nothing until every 1 kHz topic flows: the simulator holds tick 0 until then, so that no writer's
      // first samples go out before it has matched the recorder (docs/dds.md#samples-before-matching).
      if (!lockstep || !flowing()) return;
      // The newest tick seen on any topic: the socket is a FIFO, so everything sent before it has been taken
      // in (or was lost, and waiting for it would deadlock the run).
      const std::uint64_t tick = std::max({r0.lastTick(), r1.lastTick(), r2.lastTick(), r3.lastTick(), r4.lastTick(), r5.lastTick()});
      const std::uint64_t all = std::min({r0.lastTick(), r1.lastTick(), r2.lastTick(), r3.lastTick(), r4.lastTick(), r5.lastTick()});
      if (tick == progress_sent && all == progress_all_sent && ++progress_idle_loops < 10) return;  // repeat every 50 ms
      progress_idle_loops = 0;
      progress_sent = tick;
      progress_all_sent = all;
      p.publishProgress(tick, all, r0.received() + r1.received() + r2.received() + r3.received() + r4.received() + r5.received());
    };
    services::announceReady("mft-record");
    // Recording must not slow the stack: once every 1 kHz topic flows (discovery done at full priority, so
    // the first ticks are not missed), the DDS threads go to the background (--background) and the stack
    // gets the CPU first; the recorder catches up from its socket buffers. The writer thread stays as it is:
    // its queue is not covered by the lockstep window.
    bool reniced = background == Background::kNone;
    // The last half second of the scenario runs at full priority again: when the simulator exits, its
    // participant's goodbye (another socket, another thread) unmatches its writers, and samples of the last
    // ticks still waiting in a niced recorder's socket buffer would be discarded.
    const auto end_ns = static_cast<std::uint64_t>(std::max(0.0, scenario.duration_s - 0.5) * 1e9);
    bool near_end = false;
    const bool polling = cli.getInt("poll-us", 0, 100000) > 0;
    while (!services::shutdownRequested()) {
      publishProgress();
      if (!reniced && flowing()) {
        setBackground(background, nice_value, recorder.writerThreadId());
        reniced = true;
      }
      // SCHED_IDLE gets next to nothing while other work keeps every CPU busy (a parallel test run, a sweep):
      // the simulator would then wait on its window until it times out. A receive thread that has not
      // polled for 50 ms falls back to nice, as in realtime, for the rest of the run.
      if (reniced && background == Background::kIdle && !near_end && polling &&
          services::PollingUdpTransport::lastStats().sincePollNs() > 50'000'000) {
        background = Background::kNice;
        setBackground(background, nice_value, recorder.writerThreadId());
        ++starvation_fallbacks;
        std::printf("mft-record: the receive thread was starved at SCHED_IDLE: nice %ld from now on\n", nice_value);
        std::fflush(stdout);
      }
      if (reniced && background != Background::kNone && !near_end && recorder.newestStampNs() >= end_ns) {
        setBackground(Background::kNone, 0, recorder.writerThreadId());
        near_end = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    // Back to full priority to drain what is still in the socket buffers, then keep listening until the
    // topics have been quiet for linger-ms (at most 2 s): the supervisor stops every service at once when
    // the simulator ends, and the last tick's samples may still be on their way.
    if (background != Background::kNone) setBackground(Background::kNone, 0, recorder.writerThreadId());
    const auto steady = [] {
      return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
    };
    const auto give_up = steady() + 2'000'000'000LL;
    while (steady() < give_up && steady() - recorder.lastPushWallNs() < static_cast<std::int64_t>(linger_s * 1e9))
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    cpu_json = threadCpuJson();  // while the DDS threads still exist
  }  // readers gone: no more pushes
  recorder.stop();
  const auto s = recorder.stats();
  std::printf("mft-record: %llu objects, %llu ticks of GroundTruth, %llu dropped, %.2f MB in %zu piece(s): %s\n",
              static_cast<unsigned long long>(s.objects), static_cast<unsigned long long>(s.topics[0].written),
              static_cast<unsigned long long>(s.topics[0].dropped_queue + s.topics[0].tick_gaps),
              static_cast<double>(s.compressed_bytes) / 1e6, s.pieces.size(), s.pieces.empty() ? "" : s.pieces.front().c_str());
  writeSummary(cli.get("summary"), "{\"service\": \"mft-record\", \"file\": \"" + opt.output + "\", \"mode\": \"" +
                                      md.mode + "\", \"cpu_s\": " + cpu_json + ", " +
                                      pollJson(starvation_fallbacks) + ", " +
                                      recorder.summaryJson() + "}");
  return s.error.empty() ? 0 : 1;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-record", [&] { return toolMain(argc, argv); });
}
