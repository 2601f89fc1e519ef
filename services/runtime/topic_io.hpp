#pragma once
// Typed topic writers and readers on a DdsParticipant, created from a named QoS profile.
// The reader delivers every valid sample to a callback on the DDS receive thread (the cheapest path at
// 1 kHz, docs/dds.md#transport-and-qos) and counts deadline misses, liveliness changes and matched writers.
// In a chain service whose participant has the chain channel open (chain_channel.hpp), the chain topics with the
// chain's profiles go through shared memory: the writer also puts each sample in the topic's slot, and the reader
// takes them from there only (no DDS reader: a second copy would wake it twice).
#include <fastdds/rtps/common/SerializedPayload.h>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>

#include <time.h>

#include "services/runtime/dds_participant.hpp"
#include "services/runtime/deadline_counts.hpp"

namespace mft::services {

template <class M, class = void>
struct HasTickField : std::false_type {};
template <class M>
struct HasTickField<M, std::void_t<decltype(std::declval<const M&>().tick())>> : std::true_type {};

// A sample's CDR bytes from the chain channel into `msg`, through a payload reserved once (no allocation).
template <class Msg, class PubSubType>
bool fromChainBytes(PubSubType& type, eprosima::fastrtps::rtps::SerializedPayload_t& payload, const unsigned char* bytes,
                    std::size_t size, Msg* msg) {
  if (size > payload.max_size) return false;
  std::memcpy(payload.data, bytes, size);
  payload.length = static_cast<std::uint32_t>(size);
  payload.pos = 0;
  return type.deserialize(&payload, msg);
}

template <class Msg, class PubSubType>
class TopicWriter : public eprosima::fastdds::dds::DataWriterListener {
 public:
  TopicWriter(DdsParticipant& p, const std::string& topic_name, const std::string& profile) {
    auto* topic = p.topic(topic_name, new PubSubType());
    writer_ = p.publisher()->create_datawriter_with_profile(topic, profile, this);
    if (!writer_) throw DdsError("cannot create a writer on " + topic_name + " with profile " + profile);
    publisher_ = p.publisher();
    const int slot = chainSlotIndex(topic_name);
    if (p.chainChannel() && isChainWriterProfile(profile) && slot >= 0) {
      if (type_.m_typeSize > ChainChannel::kSlotBytes) throw DdsError(topic_name + " does not fit a chain channel slot");
      payload_.reserve(type_.m_typeSize);
      shm_ = std::make_unique<ChainSlotWriter>(*p.chainChannel(), slot);
    }
  }
  ~TopicWriter() override {
    if (writer_) publisher_->delete_datawriter(writer_);
  }
  TopicWriter(const TopicWriter&) = delete;
  TopicWriter& operator=(const TopicWriter&) = delete;

  bool write(const Msg& msg) {
    if (shm_) {  // the chain first: its reader runs while this process still hands the sample to DDS
      payload_.length = 0;
      payload_.pos = 0;
      if (!type_.serialize(const_cast<Msg*>(&msg), &payload_)) return false;
      shm_->write(payload_.data, payload_.length);
      if (matched_.load() == 0) return true;  // best effort, volatile: a DDS write nobody matched delivers nothing
    }
    return writer_->write(const_cast<Msg*>(&msg));
  }
  // Reliable writers: waits until every matched reader has acknowledged every sample written so far.
  bool waitForAcknowledgments(std::chrono::milliseconds timeout) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                                                            static_cast<std::uint32_t>(ns % 1000000000))) ==
           eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
  }
  int matched() const { return matched_.load() + (shm_ ? shm_->readers() : 0); }
  bool viaChainChannel() const { return shm_ != nullptr; }
  std::uint64_t offeredDeadlineMisses() const { return offered_deadline_misses_.load(); }

  void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                              const eprosima::fastdds::dds::PublicationMatchedStatus& s) override {
    matched_ = s.current_count;
  }
  void on_offered_deadline_missed(eprosima::fastdds::dds::DataWriter*,
                                  const eprosima::fastdds::dds::OfferedDeadlineMissedStatus&) override {
    ++offered_deadline_misses_;
  }

 private:
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<std::uint64_t> offered_deadline_misses_{0};
  PubSubType type_;  // serializes into the chain channel's slot
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
  std::unique_ptr<ChainSlotWriter> shm_;
};

template <class Msg, class PubSubType>
class TopicReader : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using Callback = std::function<void(const Msg&)>;
  // `delivery` matters only on the chain channel: Polled means this reader's thread is never woken for the topic;
  // the owner calls pollChannel() / awaitChannel() (DDS delivers on its own thread as always).
  TopicReader(DdsParticipant& p, const std::string& topic_name, const std::string& profile, Callback on_sample,
              ChainSlotReader::Delivery delivery = ChainSlotReader::Delivery::Woken)
      : on_sample_(std::move(on_sample)) {
    auto* topic = p.topic(topic_name, new PubSubType());
    subscriber_ = p.subscriber();
    const int slot = chainSlotIndex(topic_name);
    if (p.chainChannel() && isChainReaderProfile(profile) && slot >= 0) {
      payload_.reserve(type_.m_typeSize);
      shm_ = std::make_unique<ChainSlotReader>(*p.chainChannel(), slot,
                                               [this](const unsigned char* bytes, std::size_t size) { onBytes(bytes, size); },
                                               delivery);
      return;
    }
    reader_ = subscriber_->create_datareader_with_profile(topic, profile, this);
    if (!reader_) throw DdsError("cannot create a reader on " + topic_name + " with profile " + profile);
    const auto& period = reader_->get_qos().deadline().period;
    if (period != eprosima::fastrtps::c_TimeInfinite)
      deadline_ns_ = static_cast<std::int64_t>(period.seconds) * 1000000000 + period.nanosec;
  }
  ~TopicReader() override {
    shm_.reset();  // joins its thread before the callback's captures go
    if (reader_) subscriber_->delete_datareader(reader_);
  }
  TopicReader(const TopicReader&) = delete;
  TopicReader& operator=(const TopicReader&) = delete;

  int matched() const { return shm_ ? shm_->writers() : matched_.load(); }
  std::uint64_t received() const { return received_.load(); }
  // Requested deadline misses while the topic flowed: a gap between two samples longer than the deadline. Those
  // outside the stream (before it starts, at the first sample of a second tick, while the stack starts; after its
  // last sample, while the stack stops) are counted apart: they say nothing about the chain. Readers with a
  // deadline (the realtime chain's) only.
  std::uint64_t requestedDeadlineMisses() const { return requested_deadline_misses_.load(); }
  std::uint64_t deadlineMissesOutsideStream() const { return misses_before_stream_.load() + misses_pending_.load(); }
  // The same measured here: gaps between two consecutive samples' arrivals longer than the deadline period (0
  // without a deadline). Fast DDS's timer fires up to a millisecond early (docs/dds.md#deadline-and-liveliness-timing),
  // so its count above includes misses no sample gap shows.
  std::uint64_t gapsOverDeadline() const { return gaps_over_deadline_.load(); }
  DeadlineCounts deadlineCounts() const {
    DeadlineCounts c{requestedDeadlineMisses(), deadlineMissesOutsideStream(), gapsOverDeadline(), {}};
    std::lock_guard<std::mutex> lock(gap_mutex_);
    c.gap_windows_ns.assign(gap_windows_.begin(), gap_windows_.begin() + static_cast<std::ptrdiff_t>(gap_windows_kept_));
    return c;
  }
  int aliveWriters() const { return shm_ ? shm_->writers() : alive_writers_.load(); }
  bool viaChainChannel() const { return shm_ != nullptr; }
  // A Polled reader on the chain channel: delivers the newest sample if it is new, on the caller's thread (the
  // callback runs inside: do not hold a lock it takes). False without the channel.
  bool pollChannel() { return shm_ && shm_->poll(); }
  // A Polled reader on the chain channel: sleeps until a new sample came (delivered as pollChannel) or the timeout.
  bool awaitChannel(std::chrono::nanoseconds timeout) { return shm_ && shm_->awaitNew(timeout); }

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      ++received_;
      if (deadline_ns_ > 0) followStream();
      if (on_sample_) on_sample_(sample_);
    }
  }
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& s) override {
    matched_ = s.current_count;
  }
  void on_requested_deadline_missed(eprosima::fastdds::dds::DataReader*,
                                    const eprosima::fastdds::dds::RequestedDeadlineMissedStatus&) override {
    if (!stream_started_.load())
      ++misses_before_stream_;
    else
      ++misses_pending_;  // in the stream once another sample follows; after its end otherwise
  }
  void on_liveliness_changed(eprosima::fastdds::dds::DataReader*,
                             const eprosima::fastdds::dds::LivelinessChangedStatus& s) override {
    alive_writers_ = s.alive_count;
  }

 private:
  // The stream starts at the first sample of a second tick: before it, the simulator re-sends tick 0 until the
  // chain answers (realtime start-up), and those gaps are the stack starting, not the chain missing a deadline.
  void followStream() {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const std::int64_t ns = static_cast<std::int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
    const bool was_flowing = stream_started_.load(std::memory_order_relaxed);
    if (was_flowing && ns - last_arrival_ns_ > deadline_ns_) {
      std::lock_guard<std::mutex> lock(gap_mutex_);  // only at a gap: the 1 kHz path takes no lock
      gap_windows_[gaps_over_deadline_.load() % gap_windows_.size()] = {last_arrival_ns_, ns};
      gap_windows_kept_ = std::min(gap_windows_kept_ + 1, gap_windows_.size());
      ++gaps_over_deadline_;
    }
    if (was_flowing && misses_pending_.load(std::memory_order_relaxed) > 0)
      requested_deadline_misses_ += misses_pending_.exchange(0);
    if constexpr (HasTickField<Msg>::value) {
      if (received_.load(std::memory_order_relaxed) == 1) first_tick_ = sample_.tick();
      if (!was_flowing && sample_.tick() != first_tick_) stream_started_.store(true);
    } else {
      stream_started_.store(true);
    }
    last_arrival_ns_ = ns;
  }
  void onBytes(const unsigned char* bytes, std::size_t size) {
    if (!fromChainBytes(type_, payload_, bytes, size, &sample_)) return;
    ++received_;
    if (on_sample_) on_sample_(sample_);
  }

  Callback on_sample_;
  Msg sample_;  // persistent: never construct a message per cycle
  PubSubType type_;
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
  std::unique_ptr<ChainSlotReader> shm_;  // reset first in the destructor: its thread uses the members above
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<int> alive_writers_{0};
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> requested_deadline_misses_{0};
  std::atomic<std::uint64_t> misses_before_stream_{0}, misses_pending_{0};
  std::int64_t deadline_ns_ = 0, last_arrival_ns_ = 0;  // last_arrival_ns_, first_tick_: the receive thread's only
  std::uint64_t first_tick_ = 0;
  std::atomic<bool> stream_started_{false};
  std::atomic<std::uint64_t> gaps_over_deadline_{0};
  mutable std::mutex gap_mutex_;
  std::array<std::pair<std::int64_t, std::int64_t>, 256> gap_windows_{};  // the last 256 gaps
  std::size_t gap_windows_kept_ = 0;
};

// Waits until `ready()` holds or the timeout passes; returns whether it held.
inline bool waitUntil(const std::function<bool()>& ready, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!ready()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace mft::services
