#pragma once
// Typed topic writers and readers on a DdsParticipant, created from a named QoS profile.
// The reader delivers every valid sample to a callback on the DDS receive thread (the cheapest path at
// 1 kHz, docs/reference/dds.md#transport-and-qos) and counts deadline misses, liveliness changes and matched writers.
// In a chain service whose participant has the chain channel open (chain_channel.hpp), the chain topics with the
// chain's profiles go through shared memory: the writer puts each sample in the topic's slot and sends it over DDS
// only while a reader outside the chain is matched (the recorder, mft-inject --listen, a ROS 2 reader); the reader
// takes the stack's samples from the slot and, with a DDS reader of its own that the stack's writers do not count,
// hears writers from outside the stack (mft-inject --publish, a foreign controller): their samples reach the same
// callback. The slot lists both kinds of endpoint by GUID, so each side knows the other.
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
#include <vector>

#include <time.h>

#include "services/runtime/dds_participant.hpp"
#include "services/runtime/deadline_counts.hpp"

namespace mft::services {

template <class M, class = void>
struct HasTickField : std::false_type {};
template <class M>
struct HasTickField<M, std::void_t<decltype(std::declval<const M&>().tick())>> : std::true_type {};

// A DDS endpoint's GUID as the chain channel lists it.
inline ChainChannel::EndpointId endpointId(const eprosima::fastrtps::rtps::InstanceHandle_t& handle) {
  ChainChannel::EndpointId id{};
  const eprosima::fastrtps::rtps::octet* bytes = handle.value;
  std::memcpy(id.data(), bytes, id.size());
  return id;
}
inline ChainChannel::EndpointId endpointId(const eprosima::fastrtps::rtps::GUID_t& guid) {
  return endpointId(eprosima::fastrtps::rtps::InstanceHandle_t(guid));
}

// A match event of a DDS endpoint: the peer `handle` put on or taken off `matched` (the ids of the matched peers).
inline void followMatch(std::vector<ChainChannel::EndpointId>& matched,
                        const eprosima::fastrtps::rtps::InstanceHandle_t& handle, int count_change) {
  const ChainChannel::EndpointId id = endpointId(handle);
  const auto it = std::find(matched.begin(), matched.end(), id);
  if (count_change > 0 && it == matched.end()) matched.push_back(id);
  if (count_change < 0 && it != matched.end()) matched.erase(it);
}
// How many of `ids` are not on the slot's `list`.
inline int countNotOn(const std::vector<ChainChannel::EndpointId>& ids, const ChainChannel::EndpointList& list) {
  return static_cast<int>(std::count_if(ids.begin(), ids.end(), [&](const auto& id) { return !hasEndpoint(list, id); }));
}

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

// Where an endpoint goes: the participant, the topic (its name in the registry, idl/topics.yaml) and the QoS
// profile (a service's: ServiceContext::writing / reading).
struct TopicEndpoint {
  DdsParticipant& participant;
  std::string topic;
  std::string profile;
};

template <class Msg, class PubSubType>
class TopicWriter : public eprosima::fastdds::dds::DataWriterListener {
 public:
  explicit TopicWriter(const TopicEndpoint& e) : TopicWriter(e.participant, e.topic, e.profile) {}
  TopicWriter(DdsParticipant& p, const std::string& topic_name, const std::string& profile) {
    auto* topic = p.topic(topic_name, new PubSubType());
    publisher_ = p.publisher();
    matched_readers_.reserve(64);
    const int slot = chainSlotIndex(topic_name);
    if (p.chainChannel() && isChainWriterProfile(profile) && slot >= 0) {  // before the DDS writer: it matches at once
      if (type_.m_typeSize > ChainChannel::kSlotBytes) throw DdsError(topic_name + " does not fit a chain channel slot");
      payload_.reserve(type_.m_typeSize);
      shm_ = std::make_unique<ChainSlotWriter>(*p.chainChannel(), slot);
    }
    writer_ = publisher_->create_datawriter_with_profile(topic, profile, this);
    if (!writer_) throw DdsError("cannot create a writer on " + topic_name + " with profile " + profile);
    if (shm_) {
      id_ = endpointId(writer_->guid());
      id_place_ = addEndpoint(shm_->slot().stack_writers, id_);  // before the first write: no listener takes it twice
    }
  }
  ~TopicWriter() override {
    if (shm_) removeEndpoint(shm_->slot().stack_writers, id_place_, id_);
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
      if (outsideReaders() == 0) return true;  // best effort, volatile: such a DDS write would deliver nothing
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
  // Matched readers: over DDS, or on the chain channel plus those outside the chain over DDS.
  int matched() const { return shm_ ? shm_->readers() + outsideReaders() : matched_.load(); }
  // On the chain channel: the DDS readers this writer sends to (not the chain's own listeners).
  // Recounted only when the slot's list of listeners changed since (one atomic load otherwise: write() asks each time).
  int outsideReaders() const {
    if (shm_ && shm_->slot().chain_listeners.version.load(std::memory_order_acquire) != listeners_seen_) countOutsideReaders();
    return outside_readers_.load();
  }
  int ddsMatched() const { return matched_.load(); }  // every matched DDS reader, the chain's listeners included
  // The GUIDs of the matched DDS readers (a copy; for tools: it takes the match lock). The first 12 bytes of each
  // are its participant's GUID prefix.
  std::vector<ChainChannel::EndpointId> matchedReaders() const {
    std::lock_guard<std::mutex> lock(matched_mutex_);
    return matched_readers_;
  }
  bool viaChainChannel() const { return shm_ != nullptr; }
  std::uint64_t offeredDeadlineMisses() const { return offered_deadline_misses_.load(); }

  void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                              const eprosima::fastdds::dds::PublicationMatchedStatus& s) override {
    matched_ = s.current_count;
    {
      std::lock_guard<std::mutex> lock(matched_mutex_);  // the DDS thread's; write() takes it only after a change
      followMatch(matched_readers_, s.last_subscription_handle, s.current_count_change);
    }
    if (shm_) countOutsideReaders();
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
  // The matched DDS readers the chain's listeners are not: recounted when a reader matches or goes and when the
  // slot's list of listeners changed (a listener may match before it is on the list).
  void countOutsideReaders() const {
    std::lock_guard<std::mutex> lock(matched_mutex_);
    const ChainChannel::EndpointList& listeners = shm_->slot().chain_listeners;
    listeners_seen_ = listeners.version.load(std::memory_order_acquire);
    outside_readers_ = countNotOn(matched_readers_, listeners);
  }

  PubSubType type_;  // serializes into the chain channel's slot
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
  std::unique_ptr<ChainSlotWriter> shm_;
  ChainChannel::EndpointId id_{};
  int id_place_ = -1;
  mutable std::mutex matched_mutex_;
  std::vector<ChainChannel::EndpointId> matched_readers_;  // reserved: a match does not allocate below 64 readers
  mutable std::atomic<std::uint32_t> listeners_seen_{~0u};
  mutable std::atomic<int> outside_readers_{0};
};

template <class Msg, class PubSubType>
class TopicReader : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using Callback = std::function<void(const Msg&)>;
  // `delivery` matters only on the chain channel: Polled means this reader's thread is never woken for the topic;
  // the owner calls pollChannel() / awaitChannel(). Samples from writers outside the stack come on the DDS thread.
  TopicReader(const TopicEndpoint& e, Callback on_sample,
              ChainSlotReader::Delivery delivery = ChainSlotReader::Delivery::Woken)
      : TopicReader(e.participant, e.topic, e.profile, std::move(on_sample), delivery) {}
  TopicReader(DdsParticipant& p, const std::string& topic_name, const std::string& profile, Callback on_sample,
              ChainSlotReader::Delivery delivery = ChainSlotReader::Delivery::Woken)
      : on_sample_(std::move(on_sample)) {
    auto* topic = p.topic(topic_name, new PubSubType());
    subscriber_ = p.subscriber();
    eprosima::fastdds::dds::DataReaderQos qos;
    if (subscriber_->get_datareader_qos_from_profile(profile, qos) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      throw DdsError("cannot create a reader on " + topic_name + " with profile " + profile);
    const auto& period = qos.deadline().period;
    if (period != eprosima::fastrtps::c_TimeInfinite)
      deadline_ns_ = static_cast<std::int64_t>(period.seconds) * 1000000000 + period.nanosec;
    const int slot = chainSlotIndex(topic_name);
    if (p.chainChannel() && isChainReaderProfile(profile) && slot >= 0) {
      payload_.reserve(type_.m_typeSize);
      slot_ = &p.chainChannel()->slot(slot);
      shm_ = std::make_unique<ChainSlotReader>(*p.chainChannel(), slot,
                                               [this](const unsigned char* bytes, std::size_t size) { onBytes(bytes, size); },
                                               delivery);
      // The listener for writers outside the stack: no DDS deadline (the stack's samples do not come this way; the
      // gaps are measured on the channel), the profile's QoS otherwise, so it matches what the chain reader would.
      qos.deadline().period = eprosima::fastrtps::c_TimeInfinite;
    }
    reader_ = subscriber_->create_datareader(topic, qos, this);
    if (!reader_) throw DdsError("cannot create a reader on " + topic_name + " with profile " + profile);
    if (slot_) {
      id_ = endpointId(reader_->guid());
      id_place_ = addEndpoint(slot_->chain_listeners, id_);
    }
  }
  ~TopicReader() override {
    if (reader_) {
      reader_->set_listener(nullptr);
      subscriber_->delete_datareader(reader_);
    }
    if (slot_) removeEndpoint(slot_->chain_listeners, id_place_, id_);
    shm_.reset();  // joins its thread before the callback's captures go
  }
  TopicReader(const TopicReader&) = delete;
  TopicReader& operator=(const TopicReader&) = delete;

  // Matched writers: over DDS, or the stack's on the chain channel plus those outside the stack.
  int matched() const { return shm_ ? shm_->writers() + outsideWriters() : matched_.load(); }
  std::uint64_t received() const { return received_.load(); }
  // On the chain channel: the samples heard over DDS from writers outside the stack (included in received()).
  std::uint64_t receivedFromOutside() const { return received_from_outside_.load(); }
  // Requested deadline misses while the topic flowed: a gap between two samples longer than the deadline. Those
  // outside the stream (before it starts, at the first sample of a second tick, while the stack starts; after its
  // last sample, while the stack stops) are counted apart: they say nothing about the chain. Readers with a
  // deadline (the realtime chain's) only. On the chain channel, which has no timer, the gaps measured below.
  std::uint64_t requestedDeadlineMisses() const {
    return shm_ ? gaps_over_deadline_.load() : requested_deadline_misses_.load();
  }
  std::uint64_t deadlineMissesOutsideStream() const { return misses_before_stream_.load() + misses_pending_.load(); }
  // The same measured here: gaps between two consecutive samples' arrivals longer than the deadline period (0
  // without a deadline). Fast DDS's timer fires up to a millisecond early (docs/reference/dds.md#deadline-and-liveliness-timing),
  // so its count above includes misses no sample gap shows.
  std::uint64_t gapsOverDeadline() const { return gaps_over_deadline_.load(); }
  DeadlineCounts deadlineCounts() const {
    DeadlineCounts c{requestedDeadlineMisses(), deadlineMissesOutsideStream(), gapsOverDeadline(), {}};
    std::lock_guard<std::mutex> lock(gap_mutex_);
    c.gap_windows_ns.assign(gap_windows_.begin(), gap_windows_.begin() + static_cast<std::ptrdiff_t>(gap_windows_kept_));
    return c;
  }
  int aliveWriters() const { return shm_ ? shm_->writers() + outsideWriters() : alive_writers_.load(); }
  bool viaChainChannel() const { return shm_ != nullptr; }
  // A Polled reader on the chain channel: delivers the newest sample if it is new, on the caller's thread (the
  // callback runs inside: do not hold a lock it takes). False without the channel.
  bool pollChannel() { return shm_ && shm_->poll(); }
  // A Polled reader on the chain channel: sleeps until a new sample came (delivered as pollChannel) or the timeout.
  bool awaitChannel(std::chrono::nanoseconds timeout) { return shm_ && shm_->awaitNew(timeout); }

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    if (slot_) {  // the listener for writers outside the stack
      while (reader->take_next_sample(&outside_sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data || hasEndpoint(slot_->stack_writers, endpointId(info.publication_handle))) continue;
        ++received_from_outside_;
        std::lock_guard<std::mutex> lock(deliver_mutex_);
        deliver(outside_sample_);
      }
      return;
    }
    while (reader->take_next_sample(&sample_, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      deliver(sample_);
    }
  }
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& s) override {
    matched_ = s.current_count;
    std::lock_guard<std::mutex> lock(matched_mutex_);
    followMatch(matched_writers_, s.last_publication_handle, s.current_count_change);
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
  void followStream(const Msg& sample) {
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
      if (received_.load(std::memory_order_relaxed) == 1) first_tick_ = sample.tick();
      if (!was_flowing && sample.tick() != first_tick_) stream_started_.store(true);
    } else {
      stream_started_.store(true);
    }
    last_arrival_ns_ = ns;
  }
  void deliver(const Msg& sample) {
    ++received_;
    if (deadline_ns_ > 0) followStream(sample);
    if (on_sample_) on_sample_(sample);
  }
  // The chain channel's sample, on the slot reader's thread or the owner's (Polled). One delivery at a time: a
  // sample from outside the stack may come on the DDS thread meanwhile.
  void onBytes(const unsigned char* bytes, std::size_t size) {
    std::lock_guard<std::mutex> lock(deliver_mutex_);
    if (fromChainBytes(type_, payload_, bytes, size, &sample_)) deliver(sample_);
  }
  // Matched DDS writers that are not the stack's own (those come through the slot).
  int outsideWriters() const {
    std::lock_guard<std::mutex> lock(matched_mutex_);
    return countNotOn(matched_writers_, slot_->stack_writers);
  }

  Callback on_sample_;
  Msg sample_;          // persistent: never construct a message per cycle
  Msg outside_sample_;  // a sample from outside the stack, taken on the DDS thread
  PubSubType type_;
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
  ChainChannel::Slot* slot_ = nullptr;  // on the chain channel: the topic's slot (the participant owns the channel)
  ChainChannel::EndpointId id_{};
  int id_place_ = -1;
  std::mutex deliver_mutex_;
  mutable std::mutex matched_mutex_;
  std::vector<ChainChannel::EndpointId> matched_writers_;
  std::atomic<std::uint64_t> received_from_outside_{0};
  std::unique_ptr<ChainSlotReader> shm_;  // reset last in the destructor: its thread uses the members above
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
