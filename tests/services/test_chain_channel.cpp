// The chain's shared-memory channel (services/runtime/chain_channel.hpp): every sample arrives once, whole and
// in order through a ping-pong as the chain runs it, in one process and across two; a late reader does not get
// an earlier stack's sample; a copy torn by a concurrent write is never delivered; bad names are refused with the
// reason; the recorder's archive takes every sample in order and counts what the ring lost; the slot's lists of
// DDS endpoints find what was added and recycle the oldest place.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "services/runtime/chain_channel.hpp"
#include "tests/support/child_process.hpp"

using namespace mft::services;
using mft::test::ShmUnlink;
using mft::test::uniqueShmName;
using namespace std::chrono_literals;

namespace {


// A sample of `size` bytes whose every byte derives from `n`: a torn or stale copy shows.
std::vector<unsigned char> pattern(std::uint32_t n, std::size_t size) {
  std::vector<unsigned char> bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<unsigned char>((n * 31u + i) & 0xff);
  std::memcpy(bytes.data(), &n, sizeof n);
  return bytes;
}

// Collects delivered samples; waitFor() blocks until `count` arrived or the bound passed.
struct Inbox {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<std::vector<unsigned char>> samples;
  void add(const unsigned char* bytes, std::size_t size) {
    std::lock_guard<std::mutex> lock(mutex);
    samples.emplace_back(bytes, bytes + size);
    cv.notify_all();
  }
  bool waitFor(std::size_t count, std::chrono::milliseconds bound) {
    std::unique_lock<std::mutex> lock(mutex);
    return cv.wait_for(lock, bound, [&] { return samples.size() >= count; });
  }
};

}  // namespace

TEST(ChainChannel, NamesTheChainTopicsAndTheDiagnosticsOnly) {
  EXPECT_EQ(chainSlotIndex("SensorData"), 0);
  EXPECT_EQ(chainSlotIndex("GroundTruth"), 1);
  EXPECT_EQ(chainSlotIndex("RobotState"), 2);
  EXPECT_EQ(chainSlotIndex("Reference"), 3);
  EXPECT_EQ(chainSlotIndex("JointCommand"), 4);
  EXPECT_EQ(chainSlotIndex("WbcDiagnostics"), 5);
  EXPECT_EQ(chainSlotIndex("RecorderProgress"), -1);
  EXPECT_EQ(chainSlotIndex("OperatorCommand"), -1);
}

TEST(ChainChannel, RefusesANameShmOpenWouldNotTake) {
  for (const char* bad : {"", "/", "no-slash", "/two/slashes"}) {
    try {
      ChainChannel channel(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const ChainChannelError& e) {
      EXPECT_NE(std::string(e.what()).find("expected a name like"), std::string::npos) << e.what();
    }
  }
}

// Two mappings of one segment stand for two processes. A ping-pong of 5000 rounds, as the lockstep chain runs
// it (the writer sends the next sample once the previous one was answered): every sample arrives once, whole,
// in order; the attach counts are what the simulator waits for.
TEST(ChainChannel, PingPongDeliversEverySampleOnceAndInOrder) {
  const ShmUnlink segment{uniqueShmName("pingpong")};
  ChainChannel a(segment.name), b(segment.name);
  ChainSlotWriter ping_writer(a, 0);
  ChainSlotWriter pong_writer(b, 4);
  Inbox at_b, at_a;
  {
    ChainSlotReader ping_reader(b, 0, [&](const unsigned char* bytes, std::size_t size) {
      at_b.add(bytes, size);
      pong_writer.write(bytes, size);  // the answer carries the same bytes back
    });
    ChainSlotReader pong_reader(a, 4, [&](const unsigned char* bytes, std::size_t size) { at_a.add(bytes, size); });
    EXPECT_EQ(ping_writer.readers(), 1);
    EXPECT_EQ(ping_reader.writers(), 1);
    EXPECT_EQ(pong_reader.writers(), 1);
    constexpr std::uint32_t kRounds = 5000;
    for (std::uint32_t n = 0; n < kRounds; ++n) {
      const auto sample = pattern(n, 200 + n % 300);
      ping_writer.write(sample.data(), sample.size());
      ASSERT_TRUE(at_a.waitFor(n + 1, 5s)) << "no answer to sample " << n;
    }
    ASSERT_EQ(at_b.samples.size(), kRounds);
    ASSERT_EQ(at_a.samples.size(), kRounds);
    for (std::uint32_t n = 0; n < kRounds; ++n) {
      ASSERT_EQ(at_b.samples[n], pattern(n, 200 + n % 300)) << "sample " << n;
      ASSERT_EQ(at_a.samples[n], pattern(n, 200 + n % 300)) << "answer " << n;
    }
  }
  EXPECT_EQ(ping_writer.readers(), 0);  // detached when the readers went
}

// The same ping-pong with the answering side in a child process (fork): the futex is shared between processes.
TEST(ChainChannel, PingPongAcrossProcesses) {
  const ShmUnlink segment{uniqueShmName("fork")};
  ChainChannel parent(segment.name);
  ChainSlotWriter ping_writer(parent, 2);
  Inbox answers;
  ChainSlotReader pong_reader(parent, 3, [&](const unsigned char* bytes, std::size_t size) { answers.add(bytes, size); });
  constexpr std::uint32_t kRounds = 2000;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // echo kRounds samples, then leave
    ChainChannel channel(segment.name);
    ChainSlotWriter pong_writer(channel, 3);
    std::atomic<std::uint32_t> echoed{0};
    ChainSlotReader ping_reader(channel, 2, [&](const unsigned char* bytes, std::size_t size) {
      pong_writer.write(bytes, size);
      ++echoed;
    });
    const auto end = std::chrono::steady_clock::now() + 30s;
    while (echoed.load() < kRounds && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
    _exit(echoed.load() == kRounds ? 0 : 1);
  }
  const auto end = std::chrono::steady_clock::now() + 10s;  // the child attached: its reader counts on the slot
  while (ping_writer.readers() == 0 && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
  ASSERT_EQ(ping_writer.readers(), 1) << "the child never attached";
  bool all_answered = true;
  for (std::uint32_t n = 0; n < kRounds && all_answered; ++n) {
    const auto sample = pattern(n + 7, 96);
    ping_writer.write(sample.data(), sample.size());
    all_answered = answers.waitFor(n + 1, 5s);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(all_answered) << "answers: " << answers.samples.size();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_EQ(answers.samples.size(), kRounds);
  for (std::uint32_t n = 0; n < kRounds; ++n) ASSERT_EQ(answers.samples[n], pattern(n + 7, 96)) << "answer " << n;
}

// What a slot held before a reader attached belongs to an earlier stack (or tick): it is not delivered; the next
// write is.
TEST(ChainChannel, AReaderAttachedLaterGetsOnlyNewSamples) {
  const ShmUnlink segment{uniqueShmName("late")};
  ChainChannel channel(segment.name);
  ChainSlotWriter writer(channel, 1);
  const auto old_sample = pattern(1, 64), new_sample = pattern(2, 64);
  writer.write(old_sample.data(), old_sample.size());
  Inbox inbox;
  ChainSlotReader reader(channel, 1, [&](const unsigned char* bytes, std::size_t size) { inbox.add(bytes, size); });
  EXPECT_FALSE(inbox.waitFor(1, 100ms)) << "the earlier sample was delivered";
  writer.write(new_sample.data(), new_sample.size());
  ASSERT_TRUE(inbox.waitFor(1, 5s));
  EXPECT_EQ(inbox.samples.front(), new_sample);
}

// A writer that never waits (latest-value semantics): the reader may skip samples but never delivers a copy
// that mixes two of them, and what it delivers goes forward.
TEST(ChainChannel, NeverDeliversATornCopy) {
  const ShmUnlink segment{uniqueShmName("torn")};
  ChainChannel channel(segment.name);
  ChainSlotWriter writer(channel, 0);
  std::atomic<std::uint64_t> delivered{0}, mixed{0}, backwards{0};
  std::uint32_t last = 0;
  ChainSlotReader reader(channel, 0, [&](const unsigned char* bytes, std::size_t size) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes, sizeof n);
    if (std::vector<unsigned char>(bytes, bytes + size) != pattern(n, ChainChannel::kSlotBytes)) ++mixed;
    if (n < last) ++backwards;
    last = n;
    ++delivered;
  });
  const auto end = std::chrono::steady_clock::now() + 10s;
  for (std::uint32_t n = 1; (n < 200000 || delivered.load() < 100) && std::chrono::steady_clock::now() < end; ++n) {
    const auto sample = pattern(n, ChainChannel::kSlotBytes);
    writer.write(sample.data(), sample.size());
  }
  EXPECT_GE(delivered.load(), 100u);
  EXPECT_EQ(mixed.load(), 0u) << "torn copies retried: " << reader.torn();
  EXPECT_EQ(backwards.load(), 0u);
}

TEST(ChainChannel, RefusesASampleLargerThanItsSlot) {
  const ShmUnlink segment{uniqueShmName("large")};
  ChainChannel channel(segment.name);
  ChainSlotWriter writer(channel, 0);
  const std::vector<unsigned char> too_large(ChainChannel::kSlotBytes + 1, 0);
  EXPECT_THROW(writer.write(too_large.data(), too_large.size()), ChainChannelError);
}

// The recorder's archive: every sample in order while it drains at least once per ring; a writer that laps it
// loses the oldest samples, counted, and the archive goes on with the ones still there.
TEST(ChainChannel, ArchiveTakesEverySampleInOrderAndCountsWhatTheRingLost) {
  const ShmUnlink segment{uniqueShmName("archive")};
  ChainChannel writer_side(segment.name), recorder_side(segment.name);
  ChainSlotWriter writer(writer_side, 5);
  ChainSlotArchive archive(recorder_side, 5);
  EXPECT_EQ(writer.readers(), 1);
  std::vector<std::vector<unsigned char>> got;
  const auto keep = [&](const unsigned char* bytes, std::size_t size) { got.emplace_back(bytes, bytes + size); };
  std::uint32_t n = 0;
  for (int round = 0; round < 10; ++round) {  // 10 rounds of a full ring each
    for (std::uint32_t i = 0; i < ChainChannel::kRing; ++i, ++n) {
      const auto sample = pattern(n, 40 + n % 100);
      writer.write(sample.data(), sample.size());
    }
    EXPECT_EQ(archive.drain(keep), ChainChannel::kRing);
  }
  ASSERT_EQ(got.size(), n);
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(got[i], pattern(i, 40 + i % 100)) << "sample " << i;
  EXPECT_EQ(archive.lost(), 0u);
  // Lapped: 3 rings' worth written, the last ring is still there.
  got.clear();
  const std::uint32_t first = n;
  for (std::uint32_t i = 0; i < 3 * ChainChannel::kRing; ++i, ++n) {
    const auto sample = pattern(n, 64);
    writer.write(sample.data(), sample.size());
  }
  EXPECT_EQ(archive.drain(keep), ChainChannel::kRing);
  EXPECT_EQ(archive.lost(), 2u * ChainChannel::kRing);
  ASSERT_EQ(got.size(), ChainChannel::kRing);
  EXPECT_EQ(got.front(), pattern(first + 2 * ChainChannel::kRing, 64));
  EXPECT_EQ(got.back(), pattern(n - 1, 64));
  EXPECT_EQ(archive.drain(keep), 0u);  // nothing new
}

// The slot's lists of DDS endpoints (the stack's writers, the chain's listeners): an id is found once added and
// not after it was taken off; a restarted service's id takes the oldest place when the list is full, and taking
// the old id off then leaves the new one alone; the all-zero id is never an endpoint; every change bumps the version.
TEST(ChainChannel, EndpointListsFindWhatWasAddedAndRecycleTheOldestPlace) {
  const ShmUnlink segment{uniqueShmName("endpoints")};
  ChainChannel channel(segment.name);
  ChainChannel::EndpointList& list = channel.slot(4).stack_writers;
  auto id = [](unsigned char n) {
    ChainChannel::EndpointId e{};
    e.fill(static_cast<unsigned char>(0x10 + n));
    e[15] = n;
    return e;
  };
  EXPECT_FALSE(hasEndpoint(list, ChainChannel::EndpointId{}));
  const std::uint32_t v0 = list.version.load();
  int places[ChainChannel::kEndpoints + 1];
  for (int n = 0; n <= ChainChannel::kEndpoints; ++n) places[n] = addEndpoint(list, id(static_cast<unsigned char>(n)));
  EXPECT_EQ(list.version.load(), v0 + ChainChannel::kEndpoints + 1);
  EXPECT_EQ(places[ChainChannel::kEndpoints], places[0]);  // the list was full: the oldest place again
  EXPECT_FALSE(hasEndpoint(list, id(0)));
  for (int n = 1; n <= ChainChannel::kEndpoints; ++n) EXPECT_TRUE(hasEndpoint(list, id(static_cast<unsigned char>(n)))) << n;
  removeEndpoint(list, places[0], id(0));  // the old id's place now holds the newest: left alone
  EXPECT_TRUE(hasEndpoint(list, id(ChainChannel::kEndpoints)));
  removeEndpoint(list, places[3], id(3));
  EXPECT_FALSE(hasEndpoint(list, id(3)));
  EXPECT_EQ(list.version.load(), v0 + ChainChannel::kEndpoints + 2);
  EXPECT_FALSE(hasEndpoint(channel.slot(4).chain_listeners, id(4)));  // the two lists are apart
  ChainChannel other_process(segment.name);  // what one process added, another mapping sees
  EXPECT_TRUE(hasEndpoint(other_process.slot(4).stack_writers, id(5)));
}
