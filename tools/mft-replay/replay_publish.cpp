// mft-replay's playback: generic writers over the rawlog's message types, a read-ahead thread, the paced loop
// and its report.
#include "tools/mft-replay/replay_publish.hpp"

#include <chrono>
#include <climits>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>
#include <variant>

#include "common/install_layout.hpp"
#include "common/json_writer.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "tools/mft-replay/replay_through_wbc.hpp"

namespace mft::replay {

using Clock = std::chrono::steady_clock;

struct Publisher::Writer {
  virtual ~Writer() = default;
  virtual int matched() const = 0;
  bool stream = false;  // a 1 kHz topic (not an event)
};

namespace {

template <class M>
struct TypedWriter : Publisher::Writer {
  TypedWriter(services::DdsParticipant& p, const std::string& profile)
      : writer(p, std::string(msg::topicInfo<M>().type), profile) {}
  int matched() const override { return writer.matched(); }
  services::TopicWriter<M, typename msg::PubSubOf<M>::type> writer;
};

// The writer of rawlog topic `index` (the variant's alternative of that index: Message's order is Topic's).
template <std::size_t... I>
std::unique_ptr<Publisher::Writer> makeWriter(services::DdsParticipant& p, std::size_t index, const std::string& stream,
                                              std::index_sequence<I...>) {
  std::unique_ptr<Publisher::Writer> out;
  auto make = [&](auto tag) {
    using M = typename decltype(tag)::type;
    const bool event = msg::topicInfo<M>().qos == msg::TopicQos::Event;
    out = std::make_unique<TypedWriter<M>>(p, event ? "event_writer" : stream);
    out->stream = !event;
  };
  ((index == I ? make(msg::TypeTag<std::variant_alternative_t<I, rawlog::Message>>{}) : void()), ...);
  return out;
}

}  // namespace

Publisher::Publisher(services::DdsParticipant& p, const std::set<rawlog::Topic>& topics, const std::string& stream_profile) {
  for (rawlog::Topic t : topics) {
    const auto i = static_cast<std::size_t>(t);
    writers_[i] = makeWriter(p, i, stream_profile, std::make_index_sequence<rawlog::kNumTopics>{});
  }
}

Publisher::~Publisher() = default;

void Publisher::publish(const rawlog::Message& m) {
  std::visit([&](const auto& x) {
    using M = std::decay_t<decltype(x)>;
    if (auto* w = writers_[m.index()].get()) static_cast<TypedWriter<M>*>(w)->writer.write(x);
  }, m);
}

int Publisher::matched() const {
  int n = 0;
  for (const auto& w : writers_)
    if (w && w->stream) n += w->matched();
  return n;
}

namespace {

struct Item {
  rawlog::Message msg;
  std::int64_t rel_ns;  // since the first message played
};

// A read-ahead thread keeps file I/O and decoding off the pacing thread (docs/reference/mrpt.md#write-stalls-and-flushing: I/O hiccups).
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
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<Item> q_;
  bool done_ = false, quit_ = false;
  std::thread thread_;
};

struct Played {
  services::LatencyStats lateness_us;
  std::array<std::uint64_t, rawlog::kNumTopics> published{};
  std::uint64_t loops = 0;
  double span_s = 0.0;
  bool interrupted = false;
};

// One pass over the file at `rate`; the recorded span played.
double playOnce(rawlog::RawlogReader& reader, Publisher& publisher, const std::set<rawlog::Topic>& topics, double rate,
                double start_s, double duration_s, bool quiet, Played* p) {
  double span = 0.0;
  ReadAhead ahead(reader, topics, start_s, duration_s);
  Item item;
  const auto t0 = Clock::now();
  auto last_progress = t0;
  while (ahead.pop(&item)) {
    if (services::shutdownRequested()) {
      p->interrupted = true;
      break;
    }
    const auto due = t0 + std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(item.rel_ns) / rate));
    std::this_thread::sleep_until(due);
    publisher.publish(item.msg);
    const auto now = Clock::now();
    p->lateness_us.add(std::chrono::duration<double, std::micro>(now - due).count());
    ++p->published[static_cast<std::size_t>(rawlog::topicOf(item.msg))];
    span = static_cast<double>(item.rel_ns) * 1e-9;
    if (!quiet && now - last_progress > std::chrono::seconds(1)) {
      last_progress = now;
      std::fprintf(stderr, "\rmft-replay: %.1f s played (loop %llu), lateness p99 %.0f us   ",
                   span, static_cast<unsigned long long>(p->loops + 1), p->lateness_us.percentile(0.99));
    }
  }
  return span;
}

void printReport(const std::string& file, const config::CommandLine& cli, const std::set<rawlog::Topic>& topics,
                 const Played& p, const rawlog::RawlogReader& reader, double wall_s) {
  const double rate = cli.getDouble("rate", 1e-3, 1e3);
  const std::string end_message = reader.end() == rawlog::RawlogReader::End::None
                                      ? (p.interrupted ? "interrupted" : "stopped at --duration")
                                      : reader.endMessage();
  std::uint64_t total = 0;
  config::JsonWriter published_json;
  published_json.beginObject();
  for (std::size_t i = 0; i < rawlog::kNumTopics; ++i) {
    total += p.published[i];
    if (topics.count(static_cast<rawlog::Topic>(i)))
      published_json.field(rawlog::topicName(static_cast<rawlog::Topic>(i)), p.published[i]);
  }
  published_json.endObject();
  if (cli.isSet("json")) {
    config::JsonWriter w;
    w.beginObject().field("mode", "publish").field("file", file).field("domain", cli.getInt("domain", 0, 232));
    w.field("rate", rate, 6).field("loops", p.loops).field("messages", total).key("published").raw(published_json.str());
    w.fixedField("played_recorded_s", p.span_s, 6).fixedField("wall_s", wall_s, 6);
    w.key("lateness_us").raw(p.lateness_us.json()).field("interrupted", p.interrupted);
    w.field("end", rawlog::toString(reader.end())).field("end_message", end_message);
    std::printf("%s\n", w.endObject().str().c_str());
    return;
  }
  std::printf("replayed   %s on domain %ld at rate %g (%llu loop(s))\n", file.c_str(), cli.getInt("domain", 0, 232),
              rate, static_cast<unsigned long long>(p.loops));
  std::printf("messages   %llu: %s\n", static_cast<unsigned long long>(total), published_json.str().c_str());
  std::printf("time       %.3f s recorded in %.3f s wall\n", p.span_s, wall_s);
  std::printf("lateness   %s us\n", p.lateness_us.json().c_str());
  std::printf("file       %s\n", end_message.c_str());
}

std::set<rawlog::Topic> topicsOf(const config::CommandLine& cli) {
  std::set<rawlog::Topic> topics;
  if (!cli.isSet("topics")) {
    for (std::size_t i = 0; i < rawlog::kNumTopics; ++i) topics.insert(static_cast<rawlog::Topic>(i));
    return topics;
  }
  std::stringstream ss(cli.get("topics"));
  std::string t;
  while (std::getline(ss, t, ',')) {
    rawlog::Topic topic;
    if (t.empty()) continue;
    if (!rawlog::parseTopic(t, &topic)) cli.fail("--topics: unknown topic '" + t + "'");
    topics.insert(topic);
  }
  return topics;
}

}  // namespace

int playback(const std::string& file, std::unique_ptr<rawlog::RawlogReader> reader, const config::CommandLine& cli) {
  const std::set<rawlog::Topic> topics = topicsOf(cli);
  const double rate = cli.getDouble("rate", 1e-3, 1e3);
  const double start_s = cli.getDouble("start", 0, 1e9), duration_s = cli.getDouble("duration", 0, 1e9);
  const std::string qos = cli.get("qos");
  if (qos != "reliable" && qos != "control") cli.fail("--qos: expected reliable or control");
  const bool quiet = cli.isSet("quiet") || cli.isSet("json");
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
  Played played;
  const auto wall_start = Clock::now();
  while (true) {
    played.span_s += playOnce(*reader, publisher, topics, rate, start_s, duration_s, quiet, &played);
    ++played.loops;
    if (played.interrupted || !cli.isSet("loop") || services::shutdownRequested()) break;
    if (reader->end() == rawlog::RawlogReader::End::Corrupt) break;
    reader = std::make_unique<rawlog::RawlogReader>(file);  // start over
  }
  if (!quiet) std::fprintf(stderr, "\n");
  printReport(file, cli, topics, played, *reader, std::chrono::duration<double>(Clock::now() - wall_start).count());
  if (reader->end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-replay: the file is truncated: played up to its last whole record\n");
  if (reader->end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-replay: the file is %s\n", reader->endMessage().c_str());
    return kExitCorrupt;
  }
  return 0;
}

}  // namespace mft::replay
