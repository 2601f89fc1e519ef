// The recorder's hot path allocates nothing: once the encoder is built, encoding a message of any topic (the
// generic writer indexing into the prebuilt label tables, exact integers and text included) makes no heap
// allocation, counted through the global operator new of this test binary.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "services/record/rawlog_format.hpp"
#include "tests/support/heap_counter.hpp"

namespace mft::rawlog {
namespace {

TEST(RawlogAllocations, EncodingAMessageOfEveryTopicAllocatesNothing) {
  std::vector<Message> messages;
  for (std::size_t t = 0; t < kNumTopics; ++t) messages.push_back(emptyMessage(static_cast<Topic>(t)));
  auto& verdict = std::get<msg::CommandVerdict>(messages[static_cast<std::size_t>(Topic::CommandVerdict)]);
  std::snprintf(verdict.reason().data(), verdict.reason().size(), "z_cmd outside the reachable range");
  auto& change = std::get<msg::ConfigChange>(messages[static_cast<std::size_t>(Topic::ConfigChange)]);
  std::snprintf(change.key().data(), change.key().size(), "weights.slack");
  ObservationEncoder enc;
  for (const auto& m : messages) enc.encode(m, 1);  // first use: the static tables are built here
  std::size_t labels_written = 0;
  g_counting = true;
  for (int k = 0; k < 100; ++k)
    for (const auto& m : messages) labels_written += enc.encode(m, 1'000'000 * k).size();
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_EQ(labels_written, 100 * labels().size());
}

}  // namespace
}  // namespace mft::rawlog
