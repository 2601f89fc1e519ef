// The chain channel beside DDS (services/runtime/topic_io.hpp): a chain reader on the channel still hears a writer
// from outside the stack over DDS (what mft-inject and a foreign controller are), the stack's own writer sends
// nothing over DDS while only the chain's listeners match it, and once a reader outside the chain matches, the
// stack's samples reach it over DDS while the chain reader still takes each of them once, from the slot. The
// channel's readers measure their deadline gaps themselves (the channel has no timer).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>
#include <vector>

#include "idl/msg_pubsub.hpp"
#include "idl/msg_types.hpp"
#include "services/runtime/topic_io.hpp"

using namespace mft::services;
using namespace std::chrono_literals;

namespace {
int testDomain() { return 100 + static_cast<int>((getpid() + 37) % 100); }
using SensorWriter = TopicWriter<mft::msg::SensorData, mft::msg::SensorDataPubSubType>;
using SensorReader = TopicReader<mft::msg::SensorData, mft::msg::SensorDataPubSubType>;

struct Segment {
  std::string name = "/mft-test-outside-" + std::to_string(getpid());
  ~Segment() { shm_unlink(name.c_str()); }
};

// Two services of one stack (the simulator and the estimator) on a private domain, with the chain channel open.
struct TwoChainServices {
  Segment segment;
  DdsParticipant sim{testDomain(), MFT_DDS_PROFILES, "test_sim"};
  DdsParticipant est{testDomain(), MFT_DDS_PROFILES, "test_estimator"};
  TwoChainServices() {
    sim.openChainChannel(segment.name);
    est.openChainChannel(segment.name);
  }
};

// The ticks a reader got, in arrival order.
struct Ticks {
  std::mutex mutex;
  std::vector<std::uint64_t> got;
  void add(std::uint64_t tick) {
    std::lock_guard<std::mutex> lock(mutex);
    got.push_back(tick);
  }
  std::size_t countIn(std::uint64_t from, std::uint64_t to) {
    std::lock_guard<std::mutex> lock(mutex);
    return static_cast<std::size_t>(std::count_if(got.begin(), got.end(), [&](auto t) { return t >= from && t < to; }));
  }
  bool eachOnceIn(std::uint64_t from, std::uint64_t to) {
    std::lock_guard<std::mutex> lock(mutex);
    for (std::uint64_t t = from; t < to; ++t)
      if (std::count(got.begin(), got.end(), t) != 1) return false;
    return true;
  }
};

// The outside writer: one sample per millisecond over DDS (best effort: a loaded machine may lose a few).
void writeTicks(SensorWriter& writer, std::uint64_t from, std::uint64_t to) {
  mft::msg::SensorData m;
  for (std::uint64_t k = from; k < to; ++k) {
    m.tick(k);
    ASSERT_TRUE(writer.write(m));
    std::this_thread::sleep_for(1ms);
  }
}

// The stack's writer, as the chain runs it: the next sample once the reader has the last one (a reader on the
// channel takes the newest sample, so samples written faster than a loaded reader wakes would be skipped).
void writeTicksAnswered(SensorWriter& writer, Ticks& got, std::uint64_t from, std::uint64_t to) {
  mft::msg::SensorData m;
  for (std::uint64_t k = from; k < to; ++k) {
    m.tick(k);
    ASSERT_TRUE(writer.write(m));
    ASSERT_TRUE(waitUntil([&] { return got.countIn(k, k + 1) > 0; }, 2000ms)) << "tick " << k << " never arrived";
  }
}
}  // namespace

TEST(ChainOutsideWriters, AnOutsideWriterReachesTheChainAndTheStackSendsOverDdsOnlyToReadersOutsideIt) {
  TwoChainServices stack;
  DdsParticipant outsider(testDomain(), MFT_DDS_PROFILES, "test_inject");

  Ticks chain;
  SensorReader chain_reader(stack.est, "SensorData", "control_reader", [&](const mft::msg::SensorData& m) { chain.add(m.tick()); });
  SensorWriter stack_writer(stack.sim, "SensorData", "control_writer");
  SensorWriter outside_writer(outsider, "SensorData", "control_writer");
  ASSERT_TRUE(chain_reader.viaChainChannel());
  ASSERT_TRUE(stack_writer.viaChainChannel());
  ASSERT_FALSE(outside_writer.viaChainChannel());
  // Over DDS the stack's writer matches the chain's listener, and does not count it as a reader to send to.
  ASSERT_TRUE(waitUntil([&] { return stack_writer.ddsMatched() == 1 && outside_writer.matched() == 1 &&
                                     chain_reader.matched() == 2; }, 5000ms));
  EXPECT_EQ(stack_writer.outsideReaders(), 0);
  EXPECT_EQ(stack_writer.matched(), 1);  // the chain reader, on the channel

  writeTicksAnswered(stack_writer, chain, 1, 101);
  writeTicks(outside_writer, 1000, 1101);  // after the stack's: a DDS copy of those would have come before these
  ASSERT_TRUE(waitUntil([&] { return chain.countIn(1000, 1101) >= 90; }, 2000ms));  // best effort over loopback
  EXPECT_TRUE(chain.eachOnceIn(1, 101));                   // the stack's samples: each once, from the slot
  EXPECT_EQ(chain_reader.receivedFromOutside(), chain.countIn(1000, 1101));
  EXPECT_EQ(chain_reader.received(), 100 + chain.countIn(1000, 1101));

  // A reader outside the chain (mft-inject --listen, a recorder over DDS): now the stack's writer sends to it, and
  // the chain's listener, which hears those sends too, drops them.
  Ticks outside;
  SensorReader outside_reader(outsider, "SensorData", "control_reader", [&](const mft::msg::SensorData& m) {
    outside.add(m.tick());
  });
  ASSERT_FALSE(outside_reader.viaChainChannel());
  ASSERT_TRUE(waitUntil([&] { return stack_writer.outsideReaders() == 1; }, 5000ms));
  EXPECT_EQ(stack_writer.matched(), 2);
  writeTicksAnswered(stack_writer, chain, 2000, 2101);
  ASSERT_TRUE(waitUntil([&] { return outside.countIn(2000, 2101) >= 90; }, 2000ms));
  EXPECT_TRUE(chain.eachOnceIn(2000, 2101));
  EXPECT_EQ(chain_reader.receivedFromOutside(), chain.countIn(1000, 1101));  // none of the stack's came that way
}

TEST(ChainOutsideWriters, AChannelReaderCountsItsOwnGapsOverTheDeadline) {
  TwoChainServices stack;
  Ticks chain;
  SensorReader reader(stack.est, "SensorData", "control_reader", [&](const mft::msg::SensorData& m) { chain.add(m.tick()); });
  SensorWriter writer(stack.sim, "SensorData", "control_writer");
  writeTicksAnswered(writer, chain, 1, 21);
  const auto gaps_before = reader.gapsOverDeadline();  // a 1 ms sleep may overshoot 3 ms on a loaded machine
  std::this_thread::sleep_for(30ms);                   // a gap ten times the control_reader's 3 ms deadline
  writeTicksAnswered(writer, chain, 21, 22);
  EXPECT_EQ(reader.gapsOverDeadline(), gaps_before + 1);
  EXPECT_EQ(reader.requestedDeadlineMisses(), reader.gapsOverDeadline());  // no timer: the gaps are the misses
  const auto counts = reader.deadlineCounts();
  ASSERT_FALSE(counts.gap_windows_ns.empty());
  const auto& [from, to] = counts.gap_windows_ns.back();
  EXPECT_GE(to - from, 30'000'000);
  EXPECT_LT(to - from, 2'000'000'000);
}
