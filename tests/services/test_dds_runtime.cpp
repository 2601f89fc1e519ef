// The DDS runtime over loopback: profiles load, typed samples flow between two participants on a private
// domain, the 3 ms deadline is counted once the writer stops (outside the stream until a sample follows the gap),
// and bad inputs give clear errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>

#include <fastrtps/xmlparser/XMLProfileManager.h>

#include "idl/msg_types.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/runtime/topic_names.hpp"

using namespace mft::services;
using namespace std::chrono_literals;

namespace {
// A domain id of its own per test process, so parallel test runs never see each other.
int testDomain() { return 100 + static_cast<int>(getpid() % 100); }
using SensorWriter = TopicWriter<mft::msg::SensorData, mft::msg::SensorDataPubSubType>;
using SensorReader = TopicReader<mft::msg::SensorData, mft::msg::SensorDataPubSubType>;
}  // namespace

TEST(DdsRuntime, SamplesFlowInOrderAndDeadlineMissesAreCounted) {
  DdsParticipant sim(testDomain(), MFT_DDS_PROFILES, "test_sim");
  DdsParticipant est(testDomain(), MFT_DDS_PROFILES, "test_estimator");
  std::atomic<std::uint64_t> last_tick{0}, out_of_order{0};
  SensorReader reader(est, "SensorData", "control_reader", [&](const mft::msg::SensorData& m) {
    if (m.tick() <= last_tick.load()) ++out_of_order;
    last_tick = m.tick();
  });
  SensorWriter writer(sim, "SensorData", "control_writer");
  ASSERT_TRUE(waitUntil([&] { return writer.matched() == 1 && reader.matched() == 1; }, 5000ms));

  mft::msg::SensorData m;
  for (std::uint64_t k = 1; k <= 200; ++k) {
    m.tick(k);
    m.gyro_pitch_rate(0.001 * static_cast<double>(k));
    ASSERT_TRUE(writer.write(m));
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(waitUntil([&] { return last_tick.load() == 200; }, 2000ms));
  EXPECT_GE(reader.received(), 190u);  // best effort on loopback: at most a handful lost on a busy machine
  EXPECT_EQ(out_of_order.load(), 0u);
  const auto misses_while_flowing = reader.requestedDeadlineMisses();
  const auto outside_while_flowing = reader.deadlineMissesOutsideStream();
  // The writer stops: the 3 ms deadline must fire (about every 2 ms, docs/reference/dds.md#deadline-and-liveliness-timing),
  // counted outside the stream (a stopping stack), not as the chain's misses.
  std::this_thread::sleep_for(50ms);
  const auto outside_after_stop = reader.deadlineMissesOutsideStream();
  EXPECT_GT(outside_after_stop, outside_while_flowing + 5);
  EXPECT_EQ(reader.requestedDeadlineMisses(), misses_while_flowing);
  // A sample after the gap: the gap was inside the stream after all, and its misses move to the chain's count.
  m.tick(201);
  ASSERT_TRUE(writer.write(m));
  ASSERT_TRUE(waitUntil([&] { return last_tick.load() == 201; }, 2000ms));
  EXPECT_GE(reader.requestedDeadlineMisses(), misses_while_flowing + (outside_after_stop - outside_while_flowing));
}

TEST(DdsRuntime, BadDomainAndMissingProfilesAreClearErrors) {
  EXPECT_THROW(checkedDomainId(-1), DdsError);
  EXPECT_THROW(checkedDomainId(233), DdsError);
  EXPECT_EQ(checkedDomainId(232), 232);
  try {
    DdsParticipant p(testDomain(), "/nonexistent/profiles.xml", "x");
    FAIL();
  } catch (const DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/profiles.xml"), std::string::npos);
  }
}

TEST(DdsRuntime, UnknownWriterProfileIsAClearError) {
  DdsParticipant p(testDomain(), MFT_DDS_PROFILES, "test_bad_profile");
  EXPECT_THROW(SensorWriter(p, "SensorData", "no_such_profile"), DdsError);
}

// The recorder's polling receive path (polling_udp_transport.hpp): every sample of a burst arrives, in
// order, drained in batches rather than one wake-up per datagram; a second polling participant on the same
// domain finds its own ports (a taken port fails the bind and Fast DDS moves on, as with its own transport).
TEST(PollingReceive, BurstsArriveWholeInOrderAndInBatches) {
  // Through the sockets as between processes: Fast DDS would hand samples over inside one process.
  eprosima::fastrtps::LibrarySettingsAttributes library;
  library.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(library);
  const ReceiveTuning polling{4u << 20, std::chrono::microseconds(2000)};
  DdsParticipant sim(testDomain(), MFT_DDS_PROFILES, "test_sim");
  DdsParticipant first(testDomain(), MFT_DDS_PROFILES, "test_recorder_1", {}, polling);
  DdsParticipant second(testDomain(), MFT_DDS_PROFILES, "test_recorder_2", {}, polling);
  const PollingUdpStats& stats = PollingUdpTransport::lastStats();  // the second participant's transport
  struct Count {
    std::atomic<std::uint64_t> last{0}, out_of_order{0};
  } a, b;
  auto counter = [](Count& c) {
    return [&c](const mft::msg::SensorData& m) {
      if (m.tick() <= c.last.load()) ++c.out_of_order;
      c.last = m.tick();
    };
  };
  SensorReader reader_a(first, "SensorData", "control_reader", counter(a));
  SensorReader reader_b(second, "SensorData", "control_reader", counter(b));
  SensorWriter writer(sim, "SensorData", "control_writer");
  ASSERT_TRUE(waitUntil([&] { return writer.matched() == 2 && reader_a.matched() == 1 && reader_b.matched() == 1; }, 5000ms));
  std::this_thread::sleep_for(20ms);  // samples written in the instant of matching may be lost (docs/reference/dds.md#samples-before-matching)

  const std::uint64_t datagrams_before = stats.datagrams.load();
  mft::msg::SensorData m;
  constexpr std::uint64_t kBursts = 25, kPerBurst = 20;
  for (std::uint64_t burst = 0; burst < kBursts; ++burst) {
    for (std::uint64_t i = 1; i <= kPerBurst; ++i) {
      m.tick(burst * kPerBurst + i);
      ASSERT_TRUE(writer.write(m));
    }
    std::this_thread::sleep_for(3ms);
  }
  const std::uint64_t total = kBursts * kPerBurst;
  ASSERT_TRUE(waitUntil([&] { return a.last.load() == total && b.last.load() == total; }, 5000ms))
      << "last ticks " << a.last.load() << " and " << b.last.load();
  EXPECT_EQ(reader_a.received(), total);  // 4 MB socket buffers: nothing is lost while a poll is pending
  EXPECT_EQ(reader_b.received(), total);
  EXPECT_EQ(a.out_of_order.load(), 0u);
  EXPECT_EQ(b.out_of_order.load(), 0u);
  EXPECT_GE(stats.datagrams.load() - datagrams_before, total);
  EXPECT_GT(stats.polls.load(), 0u);
  // A burst written within one period is taken in one poll: the readers were not woken per datagram.
  EXPECT_GE(stats.max_datagrams_per_poll.load(), 5u);
}

// ROS 2's names on the wire (docs/guide/interop.md#ros-2): topic rt/mft/<snake_case>, type mft::msg::dds_::<Name>_.
TEST(DdsNames, TopicNamesAreRos2Names) {
  EXPECT_EQ(ddsTopicName("SensorData"), "rt/mft/sensor_data");
  EXPECT_EQ(ddsTopicName("WbcDiagnostics"), "rt/mft/wbc_diagnostics");
  EXPECT_EQ(ddsTopicName("OperatorCommand"), "rt/mft/operator_command");
  EXPECT_EQ(ddsTopicName("Reference"), "rt/mft/reference");
}

TEST(DdsNames, AParticipantCreatesItsTopicsUnderRos2NamesAndTypes) {
  DdsParticipant p(testDomain(), MFT_DDS_PROFILES, "test_names");
  auto* sensor = p.topic("SensorData", new mft::msg::SensorDataPubSubType());
  ASSERT_NE(sensor, nullptr);
  EXPECT_EQ(sensor->get_name(), "rt/mft/sensor_data");
  EXPECT_EQ(sensor->get_type_name(), "mft::msg::dds_::SensorData_");
  auto* verdict = p.topic("CommandVerdict", new mft::msg::CommandVerdictPubSubType());
  ASSERT_NE(verdict, nullptr);
  EXPECT_EQ(verdict->get_name(), "rt/mft/command_verdict");
  EXPECT_EQ(verdict->get_type_name(), "mft::msg::dds_::CommandVerdict_");
}
