#pragma once
// mft-inject's typed endpoints, for any topic of the registry (idl/topics.yaml): a listener that counts what it
// hears, a publisher that writes corrupted samples, and the corruption itself over the message's fields (the
// generated field visitors, mft_topics.hpp). Nothing here names a topic.
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <type_traits>

#include "idl/msg_pubsub.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::inject {

// Rare messages that must arrive (qos event in idl/topics.yaml): reliable, transient-local profiles.
inline bool isEventTopic(const std::string& type) {
  const int row = msg::topicIndex(type);
  return row >= 0 && msg::kTopics[static_cast<std::size_t>(row)].qos == msg::TopicQos::Event;
}

template <class V>
struct IsDoubleArray : std::false_type {};
template <std::size_t N>
struct IsDoubleArray<std::array<double, N>> : std::true_type {};

// Every floating-point field of a message, element by element, by the field's name.
template <class M, class F>
void eachDouble(M& m, F&& f) {
  msg::visitFields(m, [&](const char* name, auto& v) {
    using V = std::decay_t<decltype(v)>;
    if constexpr (std::is_same_v<V, double>) {
      f(name, v);
    } else if constexpr (IsDoubleArray<V>::value) {
      for (auto& d : v) f(name, d);
    }
  });
}

// A stream message's tick; an event's seq plays that role.
template <class M>
std::uint64_t tickOf(const M& m) {
  if constexpr (services::HasTickField<M>::value) return m.tick();
  else return m.seq();
}
template <class M>
void setTick(M& m, std::uint64_t t) {
  if constexpr (services::HasTickField<M>::value) m.tick(t);
  else m.seq(t);
}

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
    eachDouble(m, [&](const std::string& name, double& d) {
      if (fields.empty() || fields.count(name)) d = v;
    });
    if (kind == "range") msg::setBadValues(m);  // the registry's out-of-range enumerations and indices
  }
};

template <class M>
bool allFinite(M& m) {
  bool ok = true;
  eachDouble(m, [&](const std::string&, double& d) { ok = ok && std::isfinite(d); });
  return ok;
}

// One listened topic: counts and the largest gap between samples.
struct TopicStats {
  std::atomic<std::uint64_t> received{0}, nonfinite{0};
  std::mutex mutex;
  std::int64_t first_ns = 0, last_ns = 0, max_gap_ns = 0, max_gap_end_ns = 0;
  std::uint64_t first_tick = 0, last_tick = 0;
  void add(std::uint64_t tick, bool finite);
};

struct Listener {
  virtual ~Listener() = default;
  virtual int matched() const = 0;
  TopicStats stats;
};
// A reader that skips this process's own samples (with --follow the injector listens to the topic it writes).
template <class M>
struct TypedListener : Listener, eprosima::fastdds::dds::DataReaderListener {
  TypedListener(services::DdsParticipant& p, const std::string& topic, const std::string& profile,
                std::function<void(const M&)> also)
      : also_(std::move(also)), own_prefix_(p.get()->guid().guidPrefix), subscriber_(p.subscriber()) {
    reader_ = subscriber_->create_datareader_with_profile(p.topic(topic, new typename msg::PubSubOf<M>::type()),
                                                          profile, this);
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
template <class M>
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
  services::TopicWriter<M, typename msg::PubSubOf<M>::type> writer;
  Corruption corruption;
  std::int64_t offset;
  std::mutex mutex;
  std::condition_variable cv;
  std::thread thread;
  M latest;
  bool pending = false, stop = false;
  std::atomic<std::uint64_t> written_{0};
};

}  // namespace mft::inject
