// mft-inject: a test participant for the security tests and the fault matrix (docs/security.md, docs/faults.md).
//  --listen TOPICS        joins the domain (with no identity, or --secure DIR --identity NAME), subscribes and
//                         counts samples per topic: matched writers, received, non-finite samples, largest gap.
//                         With --wait-writers S it first waits (at most S seconds) until every listened topic has a
//                         matched writer, so that a slow discovery or secure handshake does not eat the window.
//  --publish TOPIC        publishes on TOPIC: values from --value (nan, inf, -inf, range, or a number) in the
//                         --field fields (default all floating-point fields). With --follow it copies every
//                         real sample of TOPIC and re-publishes it corrupted at once, its tick advanced by
//                         --tick-offset (so a service takes the corrupted sample as the newest one); otherwise
//                         it publishes at --rate with its own tick counter.
// It reports what happened (participant and writer created or refused, samples written, matched readers) as
// text or --json, and exits 0, or 4 when the participant or the writer was refused.
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "idl/msg_types.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "common/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

namespace {

const std::vector<std::string> kTopics = {"SensorData", "GroundTruth", "RobotState", "OperatorCommand",
                                          "Reference",  "JointCommand", "WbcDiagnostics", "Disturbance"};
bool isEventTopic(const std::string& t) { return t == "OperatorCommand" || t == "Disturbance"; }

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// Every floating-point field of a message, by name, and the small integer fields that carry an enumeration
// or an index (set out of range by --value range).
template <class A>
void each(const char* name, A& a, const std::function<void(const std::string&, double&)>& f) {
  for (auto& v : a) f(name, v);
}
void doubles(msg::SensorData& m, const std::function<void(const std::string&, double&)>& f) {
  each("actuated_pos", m.actuated_pos(), f);
  each("actuated_vel", m.actuated_vel(), f);
  each("passive_pos", m.passive_pos(), f);
  each("passive_vel", m.passive_vel(), f);
  each("sea_torque", m.sea_torque(), f);
  f("gyro_pitch_rate", m.gyro_pitch_rate());
  each("accel", m.accel(), f);
}
void doubles(msg::GroundTruth& m, const std::function<void(const std::string&, double&)>& f) {
  each("q", m.q(), f);
  each("qd", m.qd(), f);
  each("contact_force", m.contact_force(), f);
  each("lti", m.lti(), f);
}
void doubles(msg::RobotState& m, const std::function<void(const std::string&, double&)>& f) {
  each("q", m.q(), f);
  each("qd", m.qd(), f);
}
void doubles(msg::OperatorCommand& m, const std::function<void(const std::string&, double&)>& f) {
  f("z_cmd", m.z_cmd());
  f("v_cmd", m.v_cmd());
}
void doubles(msg::Reference& m, const std::function<void(const std::string&, double&)>& f) {
  f("phase", m.phase());
  each("base_z", m.base_z(), f);
  each("base_pitch", m.base_pitch(), f);
  each("foot_pos", m.foot_pos(), f);
  each("foot_vel", m.foot_vel(), f);
  each("foot_acc", m.foot_acc(), f);
  each("base_x", m.base_x(), f);
}
void doubles(msg::JointCommand& m, const std::function<void(const std::string&, double&)>& f) { each("tau", m.tau(), f); }
void doubles(msg::WbcDiagnostics& m, const std::function<void(const std::string&, double&)>& f) {
  f("solve_time_us", m.solve_time_us());
  f("tick_time_us", m.tick_time_us());
  f("slack_norm", m.slack_norm());
  each("task_error", m.task_error(), f);
  each("lti", m.lti(), f);
  each("raci", m.raci(), f);
}
void doubles(msg::Disturbance& m, const std::function<void(const std::string&, double&)>& f) {
  f("impulse", m.impulse());
  f("time_s", m.time_s());
}
void enumsOutOfRange(msg::OperatorCommand& m) { m.mode(99); }
void enumsOutOfRange(msg::Reference& m) { m.stance_leg(7); }
void enumsOutOfRange(msg::JointCommand& m) { m.mode(99); }
void enumsOutOfRange(msg::Disturbance& m) {
  m.trigger(9);
  m.leg(9);
}
template <class M>
void enumsOutOfRange(M&) {}

// Tick of the stream messages (OperatorCommand and Disturbance have none: their seq plays that role).
template <class M>
std::uint64_t tickOf(const M& m) { return m.tick(); }
std::uint64_t tickOf(const msg::OperatorCommand& m) { return m.seq(); }
std::uint64_t tickOf(const msg::Disturbance& m) { return m.seq(); }
template <class M>
void setTick(M& m, std::uint64_t t) { m.tick(t); }
void setTick(msg::OperatorCommand& m, std::uint64_t t) { m.seq(t); }
void setTick(msg::Disturbance& m, std::uint64_t t) { m.seq(t); }

struct Corruption {
  std::string kind;  // nan, inf, -inf, range, number
  double number = 0.0;
  std::set<std::string> fields;  // empty: all
  template <class M>
  void apply(M& m) const {
    double v = number;
    if (kind == "nan") v = std::numeric_limits<double>::quiet_NaN();
    else if (kind == "inf") v = std::numeric_limits<double>::infinity();
    else if (kind == "-inf") v = -std::numeric_limits<double>::infinity();
    else if (kind == "range") v = 1e6;  // finite, physically absurd (1000 km, 1 MN m, ...)
    doubles(m, [&](const std::string& name, double& d) {
      if (fields.empty() || fields.count(name)) d = v;
    });
    if (kind == "range") enumsOutOfRange(m);
  }
};

template <class M>
bool allFinite(M& m) {
  bool ok = true;
  doubles(m, [&](const std::string&, double& d) { ok = ok && std::isfinite(d); });
  return ok;
}

// One listened topic: counts and the largest gap between samples.
struct TopicStats {
  std::atomic<std::uint64_t> received{0}, nonfinite{0};
  std::mutex mutex;
  std::int64_t first_ns = 0, last_ns = 0, max_gap_ns = 0, max_gap_end_ns = 0;
  std::uint64_t first_tick = 0, last_tick = 0;
  void add(std::uint64_t tick, bool finite) {
    const std::int64_t t = nowNs();
    std::lock_guard<std::mutex> lock(mutex);
    if (received == 0) {
      first_ns = t;
      first_tick = tick;
    } else if (t - last_ns > max_gap_ns) {
      max_gap_ns = t - last_ns;
      max_gap_end_ns = t;
    }
    last_ns = t;
    last_tick = tick;
    ++received;
    if (!finite) ++nonfinite;
  }
};

struct Listener {
  virtual ~Listener() = default;
  virtual int matched() const = 0;
  TopicStats stats;
};
// A reader that skips this process's own samples (with --follow the injector listens to the topic it writes).
template <class M, class P>
struct TypedListener : Listener, eprosima::fastdds::dds::DataReaderListener {
  TypedListener(services::DdsParticipant& p, const std::string& topic, const std::string& profile,
                std::function<void(const M&)> also)
      : also_(std::move(also)), own_prefix_(p.get()->guid().guidPrefix), subscriber_(p.subscriber()) {
    reader_ = subscriber_->create_datareader_with_profile(p.topic(topic, new P()), profile, this);
    if (!reader_) throw services::DdsError("cannot create a reader on " + topic + " with profile " + profile);
  }
  ~TypedListener() override { subscriber_->delete_datareader(reader_); }
  int matched() const override { return matched_.load(); }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || info.sample_identity.writer_guid().guidPrefix == own_prefix_) continue;
      stats.add(tickOf(sample_), allFinite(sample_));
      if (also_) also_(sample_);
    }
  }
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& st) override {
    matched_ = st.current_count;
  }

 private:
  std::function<void(const M&)> also_;
  eprosima::fastrtps::rtps::GuidPrefix_t own_prefix_;
  eprosima::fastdds::dds::Subscriber* subscriber_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  M sample_;
  std::atomic<int> matched_{0};
};

struct Publisher {
  virtual ~Publisher() = default;
  virtual int matched() const = 0;
  virtual std::uint64_t written() const = 0;
  virtual void publishOwn(std::uint64_t tick) = 0;
};
template <class M, class P>
struct TypedPublisher : Publisher {
  TypedPublisher(services::DdsParticipant& p, const std::string& topic, const std::string& profile, Corruption c,
                 std::int64_t tick_offset)
      : writer(p, topic, profile), corruption(std::move(c)), offset(tick_offset) {}
  ~TypedPublisher() override {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    cv.notify_all();
    if (thread.joinable()) thread.join();
  }
  int matched() const override { return writer.matched(); }
  std::uint64_t written() const override { return written_.load(); }
  void publishOwn(std::uint64_t tick) override {
    M m;
    setTick(m, tick);
    corruption.apply(m);
    if (writer.write(m)) ++written_;
  }
  // --follow: the reader's callback hands over each real sample; a thread of its own writes the corrupted
  // copy (writing from inside the callback of a reader of the same topic stalls Fast DDS's intra-process path).
  void startFollowing() {
    thread = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex);
      while (true) {
        cv.wait(lock, [this] { return stop || pending; });
        if (stop) return;
        M m = latest;
        pending = false;
        lock.unlock();
        setTick(m, static_cast<std::uint64_t>(static_cast<std::int64_t>(tickOf(m)) + offset));
        corruption.apply(m);
        if (writer.write(m)) ++written_;
        lock.lock();
      }
    });
  }
  void post(const M& real) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      latest = real;
      pending = true;
    }
    cv.notify_one();
  }
  services::TopicWriter<M, P> writer;
  Corruption corruption;
  std::int64_t offset;
  std::mutex mutex;
  std::condition_variable cv;
  std::thread thread;
  M latest;
  bool pending = false, stop = false;
  std::atomic<std::uint64_t> written_{0};
};

std::vector<std::string> splitTopics(const std::string& text, const services::CommandLine& cli) {
  if (text == "all") return kTopics;
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string t;
  while (std::getline(ss, t, ',')) {
    if (t.empty()) continue;
    bool known = false;
    for (const auto& k : kTopics) known = known || k == t;
    if (!known) cli.fail("unknown topic '" + t + "' (one of SensorData, GroundTruth, RobotState, OperatorCommand, "
                         "Reference, JointCommand, WbcDiagnostics, Disturbance, or all)");
    out.push_back(t);
  }
  return out;
}

// Calls `f` with the message and PubSub types of a topic name.
template <class F>
void withTopicType(const std::string& topic, F&& f) {
  if (topic == "SensorData") f(msg::SensorData{}, msg::SensorDataPubSubType{});
  else if (topic == "GroundTruth") f(msg::GroundTruth{}, msg::GroundTruthPubSubType{});
  else if (topic == "RobotState") f(msg::RobotState{}, msg::RobotStatePubSubType{});
  else if (topic == "OperatorCommand") f(msg::OperatorCommand{}, msg::OperatorCommandPubSubType{});
  else if (topic == "Reference") f(msg::Reference{}, msg::ReferencePubSubType{});
  else if (topic == "JointCommand") f(msg::JointCommand{}, msg::JointCommandPubSubType{});
  else if (topic == "WbcDiagnostics") f(msg::WbcDiagnostics{}, msg::WbcDiagnosticsPubSubType{});
  else if (topic == "Disturbance") f(msg::Disturbance{}, msg::DisturbancePubSubType{});
}


}  // namespace

static int toolMain(int argc, char** argv) {
  services::CommandLine cli(
      "mft-inject",
      "Test participant for the security tests and the fault matrix (docs/security.md, docs/faults.md).\n"
      "  mft-inject --domain 190 --listen all --seconds 3 --json\n"
      "  mft-inject --domain 190 --secure DIR --identity cmd --publish JointCommand --value 20 --seconds 2\n"
      "  mft-inject --domain 190 --publish RobotState --follow --value nan --seconds 2 --json\n"
      "Exit status: 0, 2 on bad options, 4 when the participant or the writer was refused.");
  cli.option("domain", "DDS domain id (0..232)", "", true);
  cli.option("secure", "DDS Security directory (scripts/make-security.sh); default: no identity at all");
  cli.option("identity", "with --secure: the identity to use (sim, estimator, planner, wbc, record, cmd)", "cmd");
  cli.option("listen", "comma-separated topics to subscribe to and count, or 'all'");
  cli.option("publish", "the topic to publish on");
  cli.option("value", "published values: nan | inf | -inf | range (1e6 and enumerations out of range) | a number", "nan");
  cli.option("field", "comma-separated field names to set (default: every floating-point field)");
  cli.flag("follow", "re-publish every real sample of the --publish topic corrupted, at once");
  cli.option("tick-offset", "with --follow: add this to the copied tick (1: the corrupted sample is the newest)", "1");
  cli.option("rate", "without --follow: samples per second", "1000");
  cli.option("seconds", "how long to listen / publish (a listener alone stops early, and reports, on SIGTERM)", "3");
  cli.option("wait-match", "seconds to wait for a matching reader before publishing (0: do not wait)", "5");
  cli.option("wait-writers", "with --listen: seconds to wait until every listened topic has a matched writer before "
             "the --seconds window starts (0: do not wait)", "0");
  cli.option("profiles", "DDS QoS profile file",
             mft::config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES));
  cli.flag("json", "print the report as JSON");
  cli.parse(argc, argv);

  const int domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  const double seconds = cli.getDouble("seconds", 0.0, 3600.0);
  const double wait_match = cli.getDouble("wait-match", 0.0, 600.0);
  const double wait_writers = cli.getDouble("wait-writers", 0.0, 600.0);
  const double rate = cli.getDouble("rate", 0.1, 100000.0);
  const auto tick_offset = static_cast<std::int64_t>(cli.getInt("tick-offset", -1000000, 1000000000));
  const std::vector<std::string> listen = cli.isSet("listen") ? splitTopics(cli.get("listen"), cli) : std::vector<std::string>{};
  std::string publish_topic;
  if (cli.isSet("publish")) {
    const auto t = splitTopics(cli.get("publish"), cli);
    if (t.size() != 1) cli.fail("--publish takes exactly one topic");
    publish_topic = t.front();
  }
  if (listen.empty() && publish_topic.empty()) cli.fail("give --listen TOPICS and/or --publish TOPIC");
  Corruption corruption;
  corruption.kind = cli.get("value");
  if (corruption.kind != "nan" && corruption.kind != "inf" && corruption.kind != "-inf" && corruption.kind != "range") {
    corruption.number = cli.getDouble("value", -1e300, 1e300);
    corruption.kind = "number";
  }
  if (cli.isSet("field")) {
    std::stringstream ss(cli.get("field"));
    std::string f;
    while (std::getline(ss, f, ',')) if (!f.empty()) corruption.fields.insert(f);
  }
  const bool follow = cli.isSet("follow");
  if (follow && isEventTopic(publish_topic)) cli.fail("--follow needs a 1 kHz topic (" + publish_topic + " is an event topic)");
  const services::SecurityOptions security{cli.get("secure"), cli.get("identity")};
  const bool json = cli.isSet("json");

  std::string participant_status = "created", writer_status = publish_topic.empty() ? "none" : "created", error;
  std::map<std::string, std::unique_ptr<Listener>> listeners;
  std::unique_ptr<Publisher> publisher;
  std::unique_ptr<services::DdsParticipant> participant;
  int exit_code = 0;
  double matched_after_s = -1.0, writers_matched_after_s = -1.0;
  // A profile file that cannot be read is a usage error (exit 2), not a participant the stack refused (4).
  if (!std::ifstream(cli.get("profiles")).good() || std::filesystem::is_directory(cli.get("profiles")))
    cli.fail("--profiles: cannot read the DDS profile file " + cli.get("profiles"));
  try {
    participant = std::make_unique<services::DdsParticipant>(domain, cli.get("profiles"), "mft-inject", security);
  } catch (const services::DdsError& e) {
    participant_status = "refused";
    error = e.what();
    exit_code = 4;
  }
  if (participant) {
    // The publisher first, so that a --follow listener of the same topic can feed it.
    std::function<void(const void*)> feed;
    if (!publish_topic.empty()) {
      withTopicType(publish_topic, [&](auto m, auto p) {
        using M = decltype(m);
        using P = decltype(p);
        const std::string profile = isEventTopic(publish_topic) ? "event_writer" : "control_writer";
        try {
          auto pub = std::make_unique<TypedPublisher<M, P>>(*participant, publish_topic, profile, corruption, tick_offset);
          auto* raw = pub.get();
          if (follow) {
            raw->startFollowing();
            feed = [raw](const void* sample) { raw->post(*static_cast<const M*>(sample)); };
          }
          publisher = std::move(pub);
        } catch (const services::DdsError& e) {
          writer_status = "refused";
          error = e.what();
          exit_code = 4;
        }
      });
    }
    std::vector<std::string> topics = listen;
    if (follow && publisher) {
      bool present = false;
      for (const auto& t : topics) present = present || t == publish_topic;
      if (!present) topics.push_back(publish_topic);
    }
    for (const auto& t : topics) {
      withTopicType(t, [&](auto m, auto p) {
        using M = decltype(m);
        using P = decltype(p);
        std::function<void(const M&)> also;
        if (t == publish_topic && feed) also = [feed](const M& s) { feed(&s); };
        // Best effort without deadline matches the writers of both loop modes; events: reliable.
        const std::string profile = isEventTopic(t) ? "event_reader" : "lockstep_reader";
        try {
          listeners[t] = std::make_unique<TypedListener<M, P>>(*participant, t, profile, also);
        } catch (const services::DdsError& e) {
          listeners.erase(t);
          if (error.empty()) error = e.what();
          if (t != publish_topic || !follow) {
            participant_status = participant_status == "created" ? "created; reader refused on " + t : participant_status + ", " + t;
            exit_code = 4;
          }
        }
      });
    }
  }
  // A pure listener ends its window early on SIGTERM/SIGINT and still reports (a test stops it when its fault
  // is over, so that the window covers the fault exactly).
  if (participant && !publisher) services::installShutdownHandlers();
  const auto t0 = Clock::now();
  if (publisher && wait_match > 0) {
    if (services::waitUntil([&] { return publisher->matched() > 0; },
                            std::chrono::milliseconds(static_cast<long>(wait_match * 1000))))
      matched_after_s = std::chrono::duration<double>(Clock::now() - t0).count();
  }
  if (!listeners.empty() && wait_writers > 0) {
    // A secured participant matches only after its authentication handshake with each remote participant,
    // which takes longer on a loaded machine: the counting window starts once every topic has a writer.
    auto all_matched = [&] {
      for (const auto& [t, l] : listeners)
        if (l->matched() == 0) return false;
      return true;
    };
    if (services::waitUntil([&] { return all_matched() || services::shutdownRequested(); },
                            std::chrono::milliseconds(static_cast<long>(wait_writers * 1000))) && all_matched())
      writers_matched_after_s = std::chrono::duration<double>(Clock::now() - t0).count();
    // A test that must act while this participant counts waits for this line (the report comes at the end).
    std::printf("mft-inject: counting from now (%s)\n",
                writers_matched_after_s >= 0 ? "every listened topic has a writer" : "a listened topic has no writer");
    std::fflush(stdout);
  }
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration<double>(seconds);
  if (participant) {
    if (publisher && !follow) {
      const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate));
      auto next = start;
      std::uint64_t tick = 0;
      while (Clock::now() < end) {
        publisher->publishOwn(tick++);
        next += period;
        std::this_thread::sleep_until(next);
      }
    } else {
      while (Clock::now() < end && !services::shutdownRequested())
        std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the window may end up to 10 ms late
    }
  }
  // Reliable event writers: a moment for the acknowledgement before the participant goes.
  if (publisher && isEventTopic(publish_topic)) std::this_thread::sleep_for(std::chrono::milliseconds(200));

  config::JsonWriter listen_json;
  listen_json.beginObject();
  std::string listen_text;
  for (const auto& [t, l] : listeners) {
    std::lock_guard<std::mutex> lock(l->stats.mutex);
    auto& w = listen_json;
    w.key(t).beginObject().field("matched_writers", l->matched()).field("received", l->stats.received.load());
    w.field("nonfinite", l->stats.nonfinite.load()).field("first_tick", l->stats.first_tick);
    w.field("last_tick", l->stats.last_tick).fixedField("max_gap_ms", static_cast<double>(l->stats.max_gap_ns) * 1e-6, 3);
    w.field("max_gap_end_ns", l->stats.max_gap_end_ns).field("first_ns", l->stats.first_ns);
    w.field("last_ns", l->stats.last_ns).endObject();
    char buf[400];
    std::snprintf(buf, sizeof buf, "  %-16s matched writers %d, received %llu (non-finite %llu), largest gap %.1f ms\n",
                  t.c_str(), l->matched(), static_cast<unsigned long long>(l->stats.received.load()),
                  static_cast<unsigned long long>(l->stats.nonfinite.load()), static_cast<double>(l->stats.max_gap_ns) * 1e-6);
    listen_text += buf;
  }
  listen_json.endObject();
  const int matched_readers = publisher ? publisher->matched() : 0;
  const unsigned long long written = publisher ? static_cast<unsigned long long>(publisher->written()) : 0ULL;
  if (json) {
    config::JsonWriter w;
    w.beginObject().field("domain", domain).key("identity");
    if (security.enabled()) w.value(security.identity);
    else w.null();
    w.field("participant", participant_status).field("publish", publish_topic).field("writer", writer_status);
    w.field("value", cli.get("value")).field("follow", follow).field("matched_readers", matched_readers);
    w.fixedField("matched_after_s", matched_after_s, 3).field("written", written);
    w.fixedField("writers_matched_after_s", writers_matched_after_s, 3).key("listen").raw(listen_json.str());
    w.field("error", error);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("mft-inject: domain %d, identity %s: participant %s\n", domain,
                security.enabled() ? security.identity.c_str() : "(none)", participant_status.c_str());
    if (!publish_topic.empty())
      std::printf("  publish %s (%s%s): writer %s, matched readers %d, written %llu\n", publish_topic.c_str(),
                  cli.get("value").c_str(), follow ? ", follow" : "", writer_status.c_str(), matched_readers, written);
    std::fputs(listen_text.c_str(), stdout);
    if (!error.empty()) std::printf("  error: %s\n", error.c_str());
  }
  std::fflush(stdout);
  listeners.clear();  // the readers feed the publisher: they go first
  publisher.reset();
  participant.reset();
  return exit_code;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-inject", [&] { return toolMain(argc, argv); });
}
