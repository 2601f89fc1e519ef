#pragma once
// What mft-record subscribes to, one reader per topic: each DDS receive thread only copies the sample into the
// recorder's queue and keeps the topic's count and newest tick. From those, the lockstep progress it publishes.
// In a lockstep stack on the chain channel (--chain-shm), the 1 kHz topics come from the channel's rings instead
// (services/runtime/chain_channel.hpp), drained by one thread every millisecond: the writers then send nothing
// over DDS for the recorder.
// The topics are the registry's rows with `record: true` (idl/topics.yaml), the same rows the rawlog's Message
// variant is generated from (mft_rawlog_topics.hpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "services/record/record_participant.hpp"
#include "services/record/recorder.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/chain_channel.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/runtime/topic_names.hpp"

namespace mft::services {

// What the table asks of every topic, whatever its type.
class RecordedTopic {
 public:
  virtual ~RecordedTopic() = default;
  virtual std::uint64_t drainChannel(std::uint64_t max_samples) = 0;
  virtual std::uint64_t received() const = 0;
  virtual std::uint64_t lastTick() const = 0;
  virtual std::uint64_t channelLost() const = 0;
};

// One topic into the recorder.
template <class Msg, class PubSubType = typename msg::PubSubOf<Msg>::type>
class Subscription : public eprosima::fastdds::dds::DataReaderListener, public RecordedTopic {
 public:
  Subscription(RecordParticipant& p, const std::string& topic_name, const std::string& profile, rawlog::Recorder& rec,
               bool best_effort = false, ChainChannel* channel = nullptr)
      : subscriber_(p.subscriber()), recorder_(rec) {
    namespace dds = eprosima::fastdds::dds;
    if (channel && chainSlotIndex(topic_name) >= 0) {
      archive_ = std::make_unique<ChainSlotArchive>(*channel, chainSlotIndex(topic_name));
      payload_.reserve(type_.m_typeSize);
      return;
    }
    dds::TypeSupport type(new PubSubType());
    type.register_type(p.get());
    topic_ = p.get()->create_topic(ddsTopicName(topic_name), type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (!topic_) throw DdsError("cannot create the topic " + topic_name);
    dds::DataReaderQos qos;
    if (subscriber_->get_datareader_qos_from_profile(profile, qos) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      throw DdsError("no reader profile " + profile);
    if (best_effort) qos.reliability().kind = dds::BEST_EFFORT_RELIABILITY_QOS;  // matches any writer, no acks
    reader_ = subscriber_->create_datareader(topic_, qos, this);
    if (!reader_) throw DdsError("cannot create a reader on " + topic_name + " with profile " + profile);
  }
  ~Subscription() override {
    if (reader_) subscriber_->delete_datareader(reader_);
  }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      if (info.valid_data) take();
  }
  // On the chain channel: the samples written since the last call, at most `max_samples`, from the caller's (the
  // drainer's) thread; how many.
  std::uint64_t drainChannel(std::uint64_t max_samples) override {
    if (!archive_) return 0;
    return archive_->drain([this](const unsigned char* bytes, std::size_t size) {
      if (fromChainBytes(type_, payload_, bytes, size, &sample_)) take();
    }, max_samples);
  }
  std::uint64_t received() const override { return received_.load(std::memory_order_relaxed); }
  std::uint64_t lastTick() const override { return last_tick_.load(std::memory_order_relaxed); }
  std::uint64_t channelLost() const override { return archive_ ? archive_->lost() : 0; }

 private:
  void take() {
    recorder_.push(rawlog::Message(sample_));
    received_.fetch_add(1, std::memory_order_relaxed);
    if constexpr (HasTickField<Msg>::value)
      if (sample_.tick() > last_tick_.load(std::memory_order_relaxed)) last_tick_.store(sample_.tick(), std::memory_order_relaxed);
  }

  eprosima::fastdds::dds::Subscriber* subscriber_;
  rawlog::Recorder& recorder_;
  eprosima::fastdds::dds::Topic* topic_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  Msg sample_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> last_tick_{0};
  std::unique_ptr<ChainSlotArchive> archive_;
  PubSubType type_;
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
};

// Every recorded topic. The 1 kHz chain's readers use `chain_profile` (best effort with `best_effort`: the chain's
// writers offer best effort in both modes, lockstep recovers a lost sample by re-sending the tick, and a reader
// asking for more would not match; losses show as tick gaps, re-sent ticks as repeats); events use event_reader.
struct TopicTable {
  TopicTable(RecordParticipant& p, rawlog::Recorder& r, const std::string& chain_profile, bool best_effort,
             ChainChannel* channel = nullptr) {
    msg::forEachTopicType([&](auto tag) {
      using M = typename decltype(tag)::type;
      constexpr const msg::TopicInfo& info = msg::topicInfo<M>();
      if constexpr (info.recorded) {
        static_assert(std::is_constructible_v<rawlog::Message, M>, "a recorded topic the rawlog cannot hold");
        const bool stream = info.qos == msg::TopicQos::Chain;
        auto sub = std::make_unique<Subscription<M>>(p, std::string(info.type), stream ? chain_profile : "event_reader",
                                                     r, stream && best_effort, stream ? channel : nullptr);
        if (stream) streams_.emplace_back(rawlog::Message(M{}).index(), sub.get());
        all_.push_back(std::move(sub));
      }
    });
    // In the rawlog's topic order (the simulator's outputs first), the order a tick's samples are drained in.
    std::sort(streams_.begin(), streams_.end());
    if (channel) drainer_ = std::thread([this] { drainLoop(); });
  }
  ~TopicTable() {
    stop_ = true;
    if (drainer_.joinable()) drainer_.join();
  }
  // Samples the ring overwrote before the drainer took them (zero while the simulator's recorder window holds).
  std::uint64_t channelLost() const { return sum(&RecordedTopic::channelLost); }

  // Every 1 kHz topic has delivered at least one sample.
  bool flowing() const {
    for (const auto& [order, s] : streams_)
      if (!s->received()) return false;
    return true;
  }
  // The tick the simulator's window counts from. Over DDS: the newest tick seen on any 1 kHz topic (the socket is a
  // FIFO: everything sent before it has been taken in, or was lost, and waiting for it would deadlock the run).
  // On the chain channel: the newest tick seen on all of them, as each topic has its own ring, drained one after
  // the other by a background thread that may stop between two (the window must cover the slowest ring).
  std::uint64_t newestTick() const {
    if (drainer_.joinable()) return allTopicsTick();
    std::uint64_t t = 0;
    for (const auto& [order, s] : streams_) t = std::max(t, s->lastTick());
    return t;
  }
  std::uint64_t allTopicsTick() const {
    std::uint64_t t = ~std::uint64_t{0};
    for (const auto& [order, s] : streams_) t = std::min(t, s->lastTick());
    return streams_.empty() ? 0 : t;
  }
  std::uint64_t chainReceived() const { return sum(&RecordedTopic::received); }

 private:
  // A few ticks of every ring at a time, so the recorder gets the topics interleaved as over DDS: its writer
  // orders samples within a 5 ms window of simulated time (recorder.hpp), and a ring drained whole after a stall
  // (up to 200 ticks) would reach it after the other rings' newer samples were written.
  void drainChannel() {
    constexpr std::uint64_t kTicksPerPass = 2;
    std::uint64_t taken = 0;
    do {
      taken = 0;
      for (const auto& [order, s] : streams_) taken += s->drainChannel(kTicksPerPass);
    } while (taken > 0);
  }
  // Every millisecond, as the polling UDP path drains its sockets: a tick's six samples come in one pass.
  void drainLoop() {
    while (!stop_.load()) {
      drainChannel();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    drainChannel();  // what came during the last sleep
  }
  // Over the 1 kHz topics.
  std::uint64_t sum(std::uint64_t (RecordedTopic::*what)() const) const {
    std::uint64_t n = 0;
    for (const auto& [order, s] : streams_) n += (s->*what)();
    return n;
  }
  std::vector<std::unique_ptr<RecordedTopic>> all_;
  std::vector<std::pair<std::size_t, RecordedTopic*>> streams_;  // the 1 kHz topics (qos chain), by rawlog order
  std::atomic<bool> stop_{false};
  std::thread drainer_;
};

// Lockstep: publishes how far the recorder has read its socket (the simulator waits when this falls more than its
// --recorder-window behind), from the main loop every 5 ms, not per sample: no cost per tick. Nothing until every
// 1 kHz topic flows: the simulator holds tick 0 until then, so that no writer's first samples go out before it has
// matched the recorder (docs/reference/dds.md#samples-before-matching). Unchanged progress is repeated every 50 ms.
class ProgressReporter {
 public:
  void update(const TopicTable& topics, RecordParticipant& participant) {
    if (!topics.flowing()) return;
    const std::uint64_t tick = topics.newestTick(), all = topics.allTopicsTick();
    if (tick == sent_ && all == all_sent_ && ++idle_loops_ < 10) return;
    idle_loops_ = 0;
    sent_ = tick;
    all_sent_ = all;
    participant.publishProgress(tick, all, topics.chainReceived());
  }

 private:
  std::uint64_t sent_ = 0, all_sent_ = 0;
  int idle_loops_ = 0;
};

}  // namespace mft::services
