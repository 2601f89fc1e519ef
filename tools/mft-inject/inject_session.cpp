// mft-inject's run: the participant, its endpoints by the registry's topic types, the waits and the window.
#include <chrono>
#include <cstdio>
#include <thread>

#include "services/runtime/process.hpp"
#include "tools/mft-inject/inject_session.hpp"

namespace mft::inject {

using Clock = std::chrono::steady_clock;

namespace {
std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}
std::chrono::milliseconds millis(double seconds) { return std::chrono::milliseconds(static_cast<long>(seconds * 1000)); }
}  // namespace

void TopicStats::add(std::uint64_t tick, bool finite) {
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

void Session::openPublisher(const Options& o, std::function<void(const void*)>* feed) {
  writer_status = "created";
  msg::withTopicType(o.publish_topic, [&](auto tag) {
    using M = typename decltype(tag)::type;
    const std::string profile = isEventTopic(o.publish_topic) ? "event_writer" : "control_writer";
    try {
      auto pub = std::make_unique<TypedPublisher<M>>(*participant, o.publish_topic, profile, o.corruption, o.tick_offset);
      auto* raw = pub.get();
      if (o.follow) {
        raw->startFollowing();
        *feed = [raw](const void* sample) { raw->post(*static_cast<const M*>(sample)); };
      }
      publisher = std::move(pub);
    } catch (const services::DdsError& e) {
      writer_status = "refused";
      error = e.what();
      exit_code = 4;
    }
  });
}

void Session::openListener(const Options& o, const std::string& t, const std::function<void(const void*)>& feed) {
  msg::withTopicType(t, [&](auto tag) {
    using M = typename decltype(tag)::type;
    std::function<void(const M&)> also;
    if (t == o.publish_topic && feed) also = [feed](const M& s) { feed(&s); };
    // Best effort without deadline matches the writers of both loop modes; events: reliable.
    const std::string profile = isEventTopic(t) ? "event_reader" : "lockstep_reader";
    try {
      listeners[t] = std::make_unique<TypedListener<M>>(*participant, t, profile, also);
    } catch (const services::DdsError& e) {
      listeners.erase(t);
      if (error.empty()) error = e.what();
      if (t != o.publish_topic || !o.follow) {
        participant_status = participant_status == "created" ? "created; reader refused on " + t : participant_status + ", " + t;
        exit_code = 4;
      }
    }
  });
}

void Session::open(const Options& o) {
  try {
    participant = std::make_unique<services::DdsParticipant>(o.domain, o.profiles, "mft-inject", o.security);
  } catch (const services::DdsError& e) {
    participant_status = "refused";
    if (!o.publish_topic.empty()) writer_status = "created";
    error = e.what();
    exit_code = 4;
    return;
  }
  // The publisher first, so that a --follow listener of the same topic can feed it.
  std::function<void(const void*)> feed;
  if (!o.publish_topic.empty()) openPublisher(o, &feed);
  std::vector<std::string> topics = o.listen;
  if (o.follow && publisher) {
    bool present = false;
    for (const auto& t : topics) present = present || t == o.publish_topic;
    if (!present) topics.push_back(o.publish_topic);
  }
  for (const auto& t : topics) openListener(o, t, feed);
}

void Session::awaitMatches(const Options& o) {
  // A pure listener ends its window early on SIGTERM/SIGINT and still reports (a test stops it when its fault
  // is over, so that the window covers the fault exactly).
  if (participant && !publisher) services::installShutdownHandlers();
  const auto t0 = Clock::now();
  if (publisher && o.wait_match > 0) {
    if (services::waitUntil([&] { return publisher->matched() > 0; }, millis(o.wait_match)))
      matched_after_s = std::chrono::duration<double>(Clock::now() - t0).count();
  }
  if (listeners.empty() || o.wait_writers <= 0) return;
  // A secured participant matches only after its authentication handshake with each remote participant,
  // which takes longer on a loaded machine: the counting window starts once every topic has a writer.
  auto all_matched = [&] {
    for (const auto& [t, l] : listeners)
      if (l->matched() == 0) return false;
    return true;
  };
  if (services::waitUntil([&] { return all_matched() || services::shutdownRequested(); }, millis(o.wait_writers)) &&
      all_matched())
    writers_matched_after_s = std::chrono::duration<double>(Clock::now() - t0).count();
  // A test that must act while this participant counts waits for this line (the report comes at the end).
  std::printf("mft-inject: counting from now (%s)\n",
              writers_matched_after_s >= 0 ? "every listened topic has a writer" : "a listened topic has no writer");
  std::fflush(stdout);
}

void Session::runWindow(const Options& o) {
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration<double>(o.seconds);
  if (participant) {
    if (publisher && !o.follow) {
      const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate));
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
  if (publisher && isEventTopic(o.publish_topic)) std::this_thread::sleep_for(std::chrono::milliseconds(200));
}

void Session::close() {
  listeners.clear();
  publisher.reset();
  participant.reset();
}

}  // namespace mft::inject
