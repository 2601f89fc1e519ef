#pragma once
// The chain's shared-memory channel (docs/results/loop-benchmark.md, "The shared-memory chain channel"): the topics
// the chain passes along (SensorData, GroundTruth, RobotState, Reference, JointCommand) and the WBC's diagnostics
// (the rows of idl/topics.yaml with `chain: true`) go between the processes of one stack (the four chain services
// and the recorder) through a POSIX shared-memory segment the supervisor names, instead of through the DDS stack.
// Each topic has one slot: a ring of the last
// kRing samples' serialized bytes, each entry guarded by its own sequence word (a seqlock), and a head counter
// that is also the futex the chain's readers sleep on. A write is a copy and, when a reader sleeps, one
// FUTEX_WAKE: a hop costs about one thread wake-up instead of a UDP send, a receive and a listener dispatch.
//
// The chain's readers take the newest sample (in lockstep a stage writes tick k+1 only after the whole chain answered
// tick k; in realtime, as a DDS reader of history depth 1, a reader that fell behind skips to the newest);
// the recorder takes every sample in order (ChainSlotArchive), kept within the ring by the simulator's recorder
// window, and counts what the writer overwrote before it got there. One writer per slot.
//
// Each slot also lists the DDS endpoints of this stack on its topic, as opaque 16-byte ids (a GUID; no DDS here):
// the stack's writer, and the DDS readers with which the chain's readers hear writers from outside the stack
// (mft-inject, a foreign controller). The writer sends over DDS only while a reader not on that list is matched;
// a chain reader drops what it hears over DDS from a writer on the list (it has the sample from the slot).
#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "mft_topic_table.hpp"

namespace mft::services {

class ChainChannelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The slot of a topic, by the logical name TopicWriter/TopicReader are given; -1 for a topic the channel does not
// carry. The slots are the rows of the topic registry with `chain: true` (idl/topics.yaml), in its order.
int chainSlotIndex(const std::string& topic_name);

class ChainChannel {
 public:
  static constexpr std::size_t kSlotBytes = 2048;  // larger than every chain topic's serialized size (checked)
  static constexpr std::uint32_t kRing = 256;      // more than the simulator's recorder window (200 ticks)
  static constexpr int kSlots = msg::kChainSlots;

  struct Entry {
    alignas(64) std::atomic<std::uint32_t> seq;  // sample n: 2n+1 while written, 2n+2 once whole
    std::atomic<std::uint32_t> size;
    alignas(64) unsigned char data[kSlotBytes];
  };
  static constexpr int kEndpoints = 8;  // per list; a restarted service takes the oldest entry
  using EndpointId = std::array<unsigned char, 16>;
  struct EndpointList {
    std::atomic<std::uint32_t> added;    // entries ever added: the next one goes to added % kEndpoints
    std::atomic<std::uint32_t> version;  // bumped after every change, so a reader of the list knows to look again
    std::atomic<std::uint64_t> id[kEndpoints][2];
  };
  struct Slot {
    alignas(64) std::atomic<std::uint32_t> head;  // samples written so far; the futex word
    std::atomic<std::uint32_t> sleepers;          // readers inside FUTEX_WAIT (the writer wakes only then)
    std::atomic<std::uint32_t> readers;           // attached readers and writers: the channel's "matched"
    std::atomic<std::uint32_t> writers;
    EndpointList stack_writers;     // the stack's DDS writers of this topic
    EndpointList chain_listeners;   // the chain readers' DDS readers, which listen for writers outside the stack
    Entry ring[kRing];
  };

  // Opens (creating it if needed) the segment `name` ("/mft-chain-…", as shm_open takes it). Every process of
  // the stack opens the same name. The one that creates it reserves all its memory at once (posix_fallocate: a
  // full /dev/shm is an error here, not a SIGBUS at the first write to a page) and then writes the header; the
  // others wait (bounded) for the header and check it: a segment of another size, without the header (random
  // bytes), of another layout version, or made under a stack whose supervisor is gone (a stale copy) is refused.
  // Throws ChainChannelError with the reason.
  explicit ChainChannel(const std::string& name);
  ~ChainChannel();
  ChainChannel(const ChainChannel&) = delete;
  ChainChannel& operator=(const ChainChannel&) = delete;

  const std::string& name() const { return name_; }
  // Removes the name once every process of the stack has the segment mapped (the mappings stay): nothing is
  // left in /dev/shm whatever happens to the stack afterwards.
  void unlinkName() const;
  Slot& slot(int index) { return slots_[index]; }

  // The first bytes of the segment: who made it, for which layout.
  struct Header {
    std::atomic<std::uint64_t> magic;  // kMagic once the rest is written (stored last)
    std::uint32_t version;             // kVersion: the layout of the slots
    std::uint32_t reserved;
    std::uint64_t bytes;               // the whole segment
    std::int64_t creator_pid;
    std::int64_t stack_pid;            // the creator's parent: the supervisor of the stack
  };
  static constexpr std::uint64_t kMagic = 0x314e49414843544dULL;  // "MTCHAIN1"
  static constexpr std::uint32_t kVersion = 1;
  static constexpr std::size_t kHeaderBytes = 256;  // the slots start here (a multiple of their alignment)
  static std::size_t segmentBytes();

 private:
  void* create(int fd);
  void* attach(int fd);
  std::string name_;
  void* memory_ = nullptr;
  Slot* slots_ = nullptr;
};

// Puts `id` on `list`; its place, for removeEndpoint. An all-zero id is no endpoint.
int addEndpoint(ChainChannel::EndpointList& list, const ChainChannel::EndpointId& id);
// Takes the entry at `place` off `list` if it still holds `id` (a newer endpoint may have taken the place).
void removeEndpoint(ChainChannel::EndpointList& list, int place, const ChainChannel::EndpointId& id);
bool hasEndpoint(const ChainChannel::EndpointList& list, const ChainChannel::EndpointId& id);

// Copies sample `n` of `slot` into `buffer` if it is whole and still there; its size, or -1 (overwritten or
// being written).
long copyChainSample(const ChainChannel::Slot& slot, std::uint32_t n, unsigned char* buffer);

// Writes one topic's samples into its slot (the bytes given; the caller serializes).
class ChainSlotWriter {
 public:
  ChainSlotWriter(ChainChannel& channel, int slot_index);
  ~ChainSlotWriter();
  ChainSlotWriter(const ChainSlotWriter&) = delete;
  ChainSlotWriter& operator=(const ChainSlotWriter&) = delete;

  void write(const unsigned char* bytes, std::size_t size);
  int readers() const { return static_cast<int>(slot_.readers.load()); }
  ChainChannel::Slot& slot() { return slot_; }

 private:
  ChainChannel::Slot& slot_;
};

// Takes one slot's new samples and hands their bytes to `deliver`. Woken: a thread of its own sleeps on the slot
// and delivers each sample as it comes. Polled: no thread, no wake-up of this process by the writer; the owner
// calls poll() when it knows a sample is there (a topic written before the one it was woken by) or awaitNew()
// to sleep on the slot in its own thread. Samples written before it attached are not delivered (as a volatile
// DDS reader).
class ChainSlotReader {
 public:
  using Deliver = std::function<void(const unsigned char* bytes, std::size_t size)>;
  enum class Delivery { Woken, Polled };
  ChainSlotReader(ChainChannel& channel, int slot_index, Deliver deliver, Delivery delivery = Delivery::Woken);
  ~ChainSlotReader();  // stops and joins the thread
  ChainSlotReader(const ChainSlotReader&) = delete;
  ChainSlotReader& operator=(const ChainSlotReader&) = delete;

  // Polled: delivers the newest sample if it is new (on the caller's thread); whether it did. A Woken reader's own
  // thread takes every sample: false, at once (two threads taking from one reader would share its buffer).
  bool poll();
  // Polled: sleeps until a new sample is in the slot or `timeout` passed, then poll(). Woken: false, at once.
  bool awaitNew(std::chrono::nanoseconds timeout);

  int writers() const { return static_cast<int>(slot_.writers.load()); }
  ChainChannel::Slot& slot() { return slot_; }
  std::uint64_t torn() const { return torn_.load(); }  // copies retried because the writer overwrote them

 private:
  enum class Take { Delivered, Nothing, Torn };
  Take take(std::uint32_t head);
  void sleepWhile(std::uint32_t head, const struct timespec* timeout);
  void run();

  ChainChannel::Slot& slot_;
  Deliver deliver_;
  std::uint32_t last_head_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> torn_{0};
  unsigned char buffer_[ChainChannel::kSlotBytes];
  std::thread thread_;
};

// The recorder's side of a slot: every sample in the order written, taken by drain() from the owner's thread
// (no wake-ups: the recorder polls). Samples written before it attached are not taken.
class ChainSlotArchive {
 public:
  using Deliver = ChainSlotReader::Deliver;
  ChainSlotArchive(ChainChannel& channel, int slot_index);
  ~ChainSlotArchive();
  ChainSlotArchive(const ChainSlotArchive&) = delete;
  ChainSlotArchive& operator=(const ChainSlotArchive&) = delete;

  // Delivers the samples written since the last call, in order, at most `max_samples`; returns how many.
  std::uint64_t drain(const Deliver& deliver, std::uint64_t max_samples = ~std::uint64_t{0});
  std::uint64_t lost() const { return lost_; }  // overwritten before drain() got to them

 private:
  ChainChannel::Slot& slot_;
  std::uint32_t cursor_;
  std::uint64_t lost_ = 0;
  unsigned char buffer_[ChainChannel::kSlotBytes];
};

}  // namespace mft::services
