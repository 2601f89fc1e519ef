// The DDS runtime over loopback: profiles load, typed samples flow between two participants on a private
// domain, the 3 ms deadline is counted once the writer stops, and bad inputs give clear errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>

#include "MftMsgs.h"
#include "MftMsgsPubSubTypes.h"
#include "services/runtime/topic_io.hpp"

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
  // The writer stops: the 3 ms deadline must fire (about every 2 ms, DDS.md section 4).
  std::this_thread::sleep_for(50ms);
  EXPECT_GT(reader.requestedDeadlineMisses(), misses_while_flowing + 5);
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
