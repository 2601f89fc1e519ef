// mft-replay: plays an mft rawlog back onto the DDS topics with its recorded timing (rate factor, loop,
// start offset, duration, topic filter), or, with --through-wbc, feeds the recorded RobotState and Reference
// through a fresh WholeBodyController built from the recorded configuration and compares its torques with
// the recorded JointCommands (a regression check for controller changes).
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "model/mft_polytope.hpp"
#include "services/record/rawlog_reader.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/whole_body_controller.hpp"
#include "common/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kExitMismatch = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitCorrupt = 4;


// ------------------------------------------------------------------------------------------ --through-wbc
// The WBC changes applied while the run was recorded (live tuning, docs/live-tuning.md): a first pass over the
// file collects the applied ConfigChange records of mft-wbc (written some ticks after the tick they act from), and
// each becomes the controller's weights and gains from its tick on, judged by the same strict loader as live.
struct RecordedChange {
  std::uint64_t seq = 0, tick = 0;
  std::string key, value;
  wbc::WbcTuning tuning;
};
std::vector<RecordedChange> recordedWbcChanges(const std::string& path, const std::string& base_text,
                                               const model::RobotDescription& robot) {
  rawlog::RawlogReader reader(path);
  rawlog::MessageAssembler assembler(reader.metadata().time_base_unix_ns);
  mrpt::obs::CObservation::Ptr obs;
  rawlog::Message m;
  std::int64_t unix_ns = 0;
  std::vector<RecordedChange> out;
  while (reader.next(&obs)) {
    if (!assembler.add(*obs, &m, &unix_ns) || rawlog::topicOf(m) != rawlog::Topic::ConfigChange) continue;
    const auto& c = std::get<msg::ConfigChange>(m);
    if (!c.applied() || c.target() != msg::CONFIG_TARGET_WBC) continue;
    RecordedChange r;
    r.seq = c.seq();
    r.tick = c.tick();
    r.key.assign(c.key().data(), strnlen(c.key().data(), c.key().size()));
    r.value.assign(c.value().data(), strnlen(c.value().data(), c.value().size()));
    if (r.key.empty() || r.value.empty())
      throw std::runtime_error("a recorded live change (seq " + std::to_string(r.seq) + ") names no tunable key or value");
    out.push_back(r);
  }
  // In the order they took effect (seq breaks a tie: the order mft-wbc applied them in).
  std::stable_sort(out.begin(), out.end(), [](const RecordedChange& a, const RecordedChange& b) {
    return a.tick != b.tick ? a.tick < b.tick : a.seq < b.seq;
  });
  std::string text = base_text;
  for (auto& r : out) {
    auto o = wbc::applyWbcOverride(text, "recorded wbc.yaml (live change)", r.key, r.value, robot);
    r.tuning = wbc::tuningOf(o.config);
    text = o.yaml_text;
  }
  return out;
}

int throughWbc(rawlog::RawlogReader& reader, const services::CommandLine& cli) {
  const auto& md = reader.metadata();
  const bool json = cli.isSet("json");
  const double tolerance = cli.getDouble("tolerance", 0.0, 1e9);
  auto need = [&](const std::string& name) -> const std::string& {
    auto it = md.config.find(name);
    if (it == md.config.end()) {
      std::fprintf(stderr, "mft-replay: the recording has no %s in its metadata\n", name.c_str());
      std::exit(kExitBadInput);
    }
    return it->second;
  };
  std::unique_ptr<wbc::WholeBodyController> controller;
  model::RobotDescription robot;
  model::MftPolytope polytope;
  std::vector<RecordedChange> changes;
  try {
    robot = model::parseRobotDescription(need("robot.yaml"), "recorded robot.yaml");
    if (!md.robot_checksum.empty() && model::checksumHex(robot.checksum) != md.robot_checksum)
      throw std::runtime_error("the recorded robot.yaml does not match the recorded checksum " + md.robot_checksum);
    wbc::WbcConfig config = cli.isSet("wbc-config") ? wbc::loadWbcConfig(cli.get("wbc-config"))
                                                    : wbc::parseWbcConfig(need("wbc.yaml"), "recorded wbc.yaml");
    polytope = model::parseMftPolytope(need("mft_space.yaml"), "recorded mft_space.yaml", robot);
    // As mft-wbc does: the scenario chooses the variant.
    if (!wbc::parseVariant(md.controller, &config.variant))
      throw std::runtime_error("unknown recorded controller '" + md.controller + "'");
    controller = std::make_unique<wbc::WholeBodyController>(robot, config, &polytope);
    if (!cli.isSet("ignore-live-changes")) {
      std::string base_text;
      if (cli.isSet("wbc-config")) {
        std::ifstream in(cli.get("wbc-config"));
        std::stringstream ss;
        ss << in.rdbuf();
        base_text = ss.str();
      } else {
        base_text = need("wbc.yaml");
      }
      changes = recordedWbcChanges(reader.path(), base_text, robot);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mft-replay: cannot rebuild the controller from the recording: %s\n", e.what());
    return kExitBadInput;
  }
  if (md.mode != "lockstep")
    std::fprintf(stderr, "mft-replay: warning: a %s recording: the live controller may have paired states and "
                         "references differently, so differences are expected\n", md.mode.c_str());

  rawlog::MessageAssembler assembler(md.time_base_unix_ns);
  mrpt::obs::CObservation::Ptr obs;
  rawlog::Message m;
  std::int64_t unix_ns = 0;
  // mft-wbc answers tick k from RobotState(k) and Reference(k) (lockstep). The recorder stores samples in the
  // order they reached it, which on a loaded machine is not always the order they were sent (JointCommand(k)
  // can come before the Reference(k) it answers): inputs and answers are paired by tick, and the controller,
  // which carries state from tick to tick (the force-rate term, its warm start), runs the ticks in order.
  struct Tick {
    std::optional<model::RobotStateEstimate> state;
    std::optional<wbc::WbcReference> ref;
    std::optional<msg::JointCommand> command;
  };
  std::map<std::uint64_t, Tick> pending;
  // A tick still incomplete this many ticks behind the newest one never will be (the recorder reorders only
  // within a few samples).
  constexpr std::uint64_t kReorderWindow = 256;
  std::uint64_t compared = 0, unmatched = 0, mode_mismatches = 0, differing = 0;
  long long first_diff_tick = -1;
  double max_diff = 0.0, first_diff_value = 0.0;
  long long max_diff_tick = -1;
  std::size_t next_change = 0;
  auto compare = [&](const model::RobotStateEstimate& state, const wbc::WbcReference& ref, const msg::JointCommand& rec) {
    // The recorded live changes due at this tick, at the tick boundary as in mft-wbc.
    for (; next_change < changes.size() && changes[next_change].tick <= rec.tick(); ++next_change)
      controller->setTuning(changes[next_change].tuning);
    wbc::WbcDiagnostics diag;
    const model::ActuatorCommand cmd = controller->update(state, ref, &diag);
    double d = 0.0;
    for (int i = 0; i < 4; ++i) d = std::max(d, std::abs(cmd.tau[i] - rec.tau()[static_cast<std::size_t>(i)]));
    if (!(d == d)) d = std::numeric_limits<double>::infinity();
    const bool mode_differs = (cmd.mode == model::CommandMode::Damping) != (rec.mode() == msg::COMMAND_MODE_DAMPING);
    if (mode_differs) ++mode_mismatches;
    if (d > max_diff) {
      max_diff = d;
      max_diff_tick = static_cast<long long>(rec.tick());
    }
    if (d > tolerance || mode_differs) {
      ++differing;
      if (first_diff_tick < 0) {
        first_diff_tick = static_cast<long long>(rec.tick());
        first_diff_value = d;
      }
    }
    ++compared;
  };
  // Runs every complete tick at the front; drops a front tick that can no longer complete (`newest` is the
  // newest tick seen; all: at the end of the file). A dropped tick with a command counts as unmatched.
  auto drain = [&](std::uint64_t newest, bool all) {
    while (!pending.empty()) {
      auto& [tick, t] = *pending.begin();
      if (t.state && t.ref && t.command) {
        compare(*t.state, *t.ref, *t.command);
      } else if (all || newest > tick + kReorderWindow) {
        if (t.command) ++unmatched;
      } else {
        break;
      }
      pending.erase(pending.begin());
    }
  };
  std::uint64_t newest = 0;
  while (reader.next(&obs)) {
    if (!assembler.add(*obs, &m, &unix_ns)) continue;
    std::uint64_t tick = 0;
    switch (rawlog::topicOf(m)) {
      case rawlog::Topic::RobotState: {
        model::RobotStateEstimate state;
        services::fromMsg(std::get<msg::RobotState>(m), &state);
        tick = state.tick;
        pending[tick].state = state;
        break;
      }
      case rawlog::Topic::Reference: {
        wbc::WbcReference ref;
        services::fromMsg(std::get<msg::Reference>(m), &ref);
        tick = ref.tick;
        pending[tick].ref = ref;
        break;
      }
      case rawlog::Topic::JointCommand:
        tick = std::get<msg::JointCommand>(m).tick();
        pending[tick].command = std::get<msg::JointCommand>(m);
        break;
      default:
        continue;
    }
    newest = std::max(newest, tick);
    drain(newest, false);
  }
  drain(newest, true);
  const bool ok = compared > 0 && differing == 0;
  if (json) {
    config::JsonWriter w;
    w.beginObject().field("mode", "through-wbc").field("file", reader.path()).field("ticks_compared", compared);
    w.field("unmatched_commands", unmatched).field("max_abs_diff_Nm", max_diff, 17).field("max_diff_tick", max_diff_tick);
    w.field("tolerance", tolerance, 17).field("differing_ticks", differing).field("first_differing_tick", first_diff_tick);
    w.field("first_difference_Nm", first_diff_value, 17).field("mode_mismatches", mode_mismatches);
    w.field("live_changes", changes.size()).field("live_changes_applied", next_change);
    w.field("end", rawlog::toString(reader.end())).field("end_message", reader.endMessage()).field("ok", ok);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("through-wbc  %s (%s, controller %s)\n", reader.path().c_str(), md.mode.c_str(), md.controller.c_str());
    std::printf("compared     %llu ticks (%llu commands without their state/reference)\n",
                static_cast<unsigned long long>(compared), static_cast<unsigned long long>(unmatched));
    std::printf("max |dtau|   %.3g N m (tick %lld), tolerance %.3g N m\n", max_diff, max_diff_tick, tolerance);
    for (const auto& c : changes)
      std::printf("live change  wbc.%s = %s from tick %llu\n", c.key.c_str(), c.value.c_str(),
                  static_cast<unsigned long long>(c.tick));
    if (differing) std::printf("DIFFERENT    %llu ticks, first at tick %lld (%.3g N m)\n",
                               static_cast<unsigned long long>(differing), first_diff_tick, first_diff_value);
    else std::printf("identical    within the tolerance\n");
    std::printf("file         %s\n", reader.endMessage().c_str());
  }
  if (reader.end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-replay: the file is truncated: compared up to its last whole record\n");
  if (reader.end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-replay: the file is %s\n", reader.endMessage().c_str());
    return kExitCorrupt;
  }
  if (compared == 0) std::fprintf(stderr, "mft-replay: no JointCommand could be compared\n");
  return ok ? 0 : kExitMismatch;
}

// ------------------------------------------------------------------------------------------------- publish
struct Item {
  rawlog::Message msg;
  std::int64_t rel_ns;  // since the first message played
};

class Publisher {
 public:
  Publisher(services::DdsParticipant& p, const std::set<rawlog::Topic>& topics, const std::string& chain_profile) {
    auto want = [&](rawlog::Topic t) { return topics.count(t) > 0; };
    using rawlog::Topic;
    if (want(Topic::GroundTruth)) gt_ = std::make_unique<decltype(gt_)::element_type>(p, "GroundTruth", chain_profile);
    if (want(Topic::SensorData)) sd_ = std::make_unique<decltype(sd_)::element_type>(p, "SensorData", chain_profile);
    if (want(Topic::RobotState)) rs_ = std::make_unique<decltype(rs_)::element_type>(p, "RobotState", chain_profile);
    if (want(Topic::Reference)) rf_ = std::make_unique<decltype(rf_)::element_type>(p, "Reference", chain_profile);
    if (want(Topic::JointCommand)) jc_ = std::make_unique<decltype(jc_)::element_type>(p, "JointCommand", chain_profile);
    if (want(Topic::WbcDiagnostics)) wd_ = std::make_unique<decltype(wd_)::element_type>(p, "WbcDiagnostics", chain_profile);
    if (want(Topic::OperatorCommand)) oc_ = std::make_unique<decltype(oc_)::element_type>(p, "OperatorCommand", "event_writer");
    if (want(Topic::Disturbance)) db_ = std::make_unique<decltype(db_)::element_type>(p, "Disturbance", "event_writer");
    if (want(Topic::ConfigChange)) cc_ = std::make_unique<decltype(cc_)::element_type>(p, "ConfigChange", "event_writer");
  }
  void publish(const rawlog::Message& m) {
    std::visit(
        [this](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, msg::GroundTruth>) gt_->write(x);
          else if constexpr (std::is_same_v<T, msg::SensorData>) sd_->write(x);
          else if constexpr (std::is_same_v<T, msg::RobotState>) rs_->write(x);
          else if constexpr (std::is_same_v<T, msg::Reference>) rf_->write(x);
          else if constexpr (std::is_same_v<T, msg::JointCommand>) jc_->write(x);
          else if constexpr (std::is_same_v<T, msg::WbcDiagnostics>) wd_->write(x);
          else if constexpr (std::is_same_v<T, msg::OperatorCommand>) oc_->write(x);
          else if constexpr (std::is_same_v<T, msg::ConfigChange>) cc_->write(x);
          else db_->write(x);
        },
        m);
  }
  int matched() const {
    int n = 0;
    for (int v : {gt_ ? gt_->matched() : 0, sd_ ? sd_->matched() : 0, rs_ ? rs_->matched() : 0, rf_ ? rf_->matched() : 0,
                  jc_ ? jc_->matched() : 0, wd_ ? wd_->matched() : 0})
      n += v;
    return n;
  }

 private:
  std::unique_ptr<services::TopicWriter<msg::GroundTruth, msg::GroundTruthPubSubType>> gt_;
  std::unique_ptr<services::TopicWriter<msg::SensorData, msg::SensorDataPubSubType>> sd_;
  std::unique_ptr<services::TopicWriter<msg::RobotState, msg::RobotStatePubSubType>> rs_;
  std::unique_ptr<services::TopicWriter<msg::Reference, msg::ReferencePubSubType>> rf_;
  std::unique_ptr<services::TopicWriter<msg::JointCommand, msg::JointCommandPubSubType>> jc_;
  std::unique_ptr<services::TopicWriter<msg::WbcDiagnostics, msg::WbcDiagnosticsPubSubType>> wd_;
  std::unique_ptr<services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType>> oc_;
  std::unique_ptr<services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType>> db_;
  std::unique_ptr<services::TopicWriter<msg::ConfigChange, msg::ConfigChangePubSubType>> cc_;
};

// A read-ahead thread keeps file I/O and decoding off the pacing thread (docs/mrpt.md#write-stalls-and-flushing: I/O hiccups).
class ReadAhead {
 public:
  ReadAhead(rawlog::RawlogReader& reader, const std::set<rawlog::Topic>& topics, double start_s, double duration_s)
      : reader_(reader), topics_(topics), start_ns_(static_cast<std::int64_t>(start_s * 1e9)),
        end_ns_(duration_s > 0 ? start_ns_ + static_cast<std::int64_t>(duration_s * 1e9) : INT64_MAX),
        thread_([this] { run(); }) {}
  ~ReadAhead() {
    {
      std::lock_guard<std::mutex> l(m_);
      quit_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  // Blocks until an item is there; false at the end.
  bool pop(Item* out) {
    std::unique_lock<std::mutex> l(m_);
    cv_.wait(l, [&] { return !q_.empty() || done_; });
    if (q_.empty()) return false;
    *out = std::move(q_.front());
    q_.pop_front();
    cv_.notify_all();
    return true;
  }
  double recordedSpanS() const { return static_cast<double>(std::min(last_rel_, end_ns_) - start_ns_) * 1e-9; }

 private:
  void run() {
    rawlog::MessageAssembler assembler(reader_.metadata().time_base_unix_ns);
    mrpt::obs::CObservation::Ptr obs;
    rawlog::Message m;
    std::int64_t unix_ns = 0, first = -1;
    while (reader_.next(&obs)) {
      if (!assembler.add(*obs, &m, &unix_ns)) continue;
      if (first < 0) first = unix_ns;
      const std::int64_t rel = unix_ns - first;
      last_rel_ = rel;
      if (rel < start_ns_ || !topics_.count(rawlog::topicOf(m))) continue;
      if (rel > end_ns_) break;
      std::unique_lock<std::mutex> l(m_);
      cv_.wait(l, [&] { return q_.size() < 4096 || quit_; });
      if (quit_) break;
      q_.push_back({m, rel - start_ns_});
      cv_.notify_all();
    }
    std::lock_guard<std::mutex> l(m_);
    done_ = true;
    cv_.notify_all();
  }
  rawlog::RawlogReader& reader_;
  std::set<rawlog::Topic> topics_;
  std::int64_t start_ns_, end_ns_;
  std::int64_t last_rel_ = 0;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<Item> q_;
  bool done_ = false, quit_ = false;
  std::thread thread_;
};

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
           "(docs/live-tuning.md); by default each acts from its recorded tick");
  cli.flag("json", "print the result as JSON");
  cli.parse(argc, argv);
  if (file.empty()) file = cli.get("file");
  if (file.empty()) cli.fail("no rawlog given");

  std::unique_ptr<rawlog::RawlogReader> reader;
  try {
    reader = std::make_unique<rawlog::RawlogReader>(file);
  } catch (const rawlog::NotMftRawlog& e) {
    std::fprintf(stderr, "mft-replay: refused: %s\n", e.what());
    return kExitBadInput;
  }
  if (cli.isSet("through-wbc")) return throughWbc(*reader, cli);

  std::set<rawlog::Topic> topics;
  if (cli.isSet("topics")) {
    std::stringstream ss(cli.get("topics"));
    std::string t;
    while (std::getline(ss, t, ',')) {
      rawlog::Topic topic;
      if (t.empty()) continue;
      if (!rawlog::parseTopic(t, &topic)) cli.fail("--topics: unknown topic '" + t + "'");
      topics.insert(topic);
    }
  } else {
    for (std::size_t i = 0; i < rawlog::kNumTopics; ++i) topics.insert(static_cast<rawlog::Topic>(i));
  }
  const double rate = cli.getDouble("rate", 1e-3, 1e3);
  const double start_s = cli.getDouble("start", 0, 1e9), duration_s = cli.getDouble("duration", 0, 1e9);
  const std::string qos = cli.get("qos");
  if (qos != "reliable" && qos != "control") cli.fail("--qos: expected reliable or control");
  const bool json = cli.isSet("json"), quiet = cli.isSet("quiet") || json;
  services::installShutdownHandlers();
  if (cli.isSet("rt")) services::tryRealtimeScheduling(80);

  std::unique_ptr<services::DdsParticipant> participant;
  try {
    participant = std::make_unique<services::DdsParticipant>(static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId)),
                                                             config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES),
                                                             "mft-replay");
  } catch (const services::DdsError& e) {
    cli.fail(e.what());
  }
  Publisher publisher(*participant, topics, qos == "reliable" ? "reliable_writer" : "control_writer");
  const double wait_s = cli.getDouble("wait-subscribers", 0, 3600);
  if (wait_s > 0 && !services::waitUntil([&] { return publisher.matched() > 0; },
                                         std::chrono::milliseconds(static_cast<long>(wait_s * 1000))))
    std::fprintf(stderr, "mft-replay: no subscriber after %.1f s; playing anyway\n", wait_s);

  services::LatencyStats lateness_us;
  std::array<std::uint64_t, rawlog::kNumTopics> published{};
  std::uint64_t loops = 0;
  double played_span_s = 0.0;
  const auto wall_start = Clock::now();
  bool interrupted = false;
  while (true) {
    double span = 0.0;
    {
      ReadAhead ahead(*reader, topics, start_s, duration_s);
      Item item;
      const auto t0 = Clock::now();
      auto last_progress = t0;
      while (ahead.pop(&item)) {
        if (services::shutdownRequested()) {
          interrupted = true;
          break;
        }
        const auto due = t0 + std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(item.rel_ns) / rate));
        std::this_thread::sleep_until(due);
        publisher.publish(item.msg);
        const auto now = Clock::now();
        lateness_us.add(std::chrono::duration<double, std::micro>(now - due).count());
        ++published[static_cast<std::size_t>(rawlog::topicOf(item.msg))];
        span = static_cast<double>(item.rel_ns) * 1e-9;
        if (!quiet && now - last_progress > std::chrono::seconds(1)) {
          last_progress = now;
          std::fprintf(stderr, "\rmft-replay: %.1f s played (loop %llu), lateness p99 %.0f us   ",
                       span, static_cast<unsigned long long>(loops + 1), lateness_us.percentile(0.99));
        }
      }
    }
    played_span_s += span;
    ++loops;
    if (interrupted || !cli.isSet("loop") || services::shutdownRequested()) break;
    if (reader->end() == rawlog::RawlogReader::End::Corrupt) break;
    reader = std::make_unique<rawlog::RawlogReader>(file);  // start over
  }
  if (!quiet) std::fprintf(stderr, "\n");
  const std::string end_message = reader->end() == rawlog::RawlogReader::End::None
                                      ? (interrupted ? "interrupted" : "stopped at --duration")
                                      : reader->endMessage();
  const double wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  std::uint64_t total = 0;
  config::JsonWriter published_json;
  published_json.beginObject();
  for (std::size_t i = 0; i < rawlog::kNumTopics; ++i) {
    total += published[i];
    if (!topics.count(static_cast<rawlog::Topic>(i))) continue;
    const std::string name = rawlog::topicName(static_cast<rawlog::Topic>(i));
    published_json.field(name, published[i]);
  }
  published_json.endObject();
  if (json) {
    config::JsonWriter w;
    w.beginObject().field("mode", "publish").field("file", file).field("domain", cli.getInt("domain", 0, 232));
    w.field("rate", rate, 6).field("loops", loops).field("messages", total).key("published").raw(published_json.str());
    w.fixedField("played_recorded_s", played_span_s, 6).fixedField("wall_s", wall_s, 6);
    w.key("lateness_us").raw(lateness_us.json()).field("interrupted", interrupted);
    w.field("end", rawlog::toString(reader->end())).field("end_message", end_message);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("replayed   %s on domain %ld at rate %g (%llu loop(s))\n", file.c_str(), cli.getInt("domain", 0, 232),
                rate, static_cast<unsigned long long>(loops));
    std::printf("messages   %llu: %s\n", static_cast<unsigned long long>(total), published_json.str().c_str());
    std::printf("time       %.3f s recorded in %.3f s wall\n", played_span_s, wall_s);
    std::printf("lateness   %s us\n", lateness_us.json().c_str());
    std::printf("file       %s\n", end_message.c_str());
  }
  if (reader->end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-replay: the file is truncated: played up to its last whole record\n");
  if (reader->end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-replay: the file is %s\n", reader->endMessage().c_str());
    return kExitCorrupt;
  }
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-replay", [&] { return toolMain(argc, argv); });
}
