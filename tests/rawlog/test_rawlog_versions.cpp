// Recordings made before stay readable: tests/data/rawlog/schema1.rawlog was written by the schema-1 recorder
// (hand-written channel tables, integers as doubles) from rawlog_fixture.hpp's messages; today's reader gives
// back exactly those messages, with the same labels and columns.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "services/record/rawlog_reader.hpp"
#include "tests/rawlog/rawlog_fixture.hpp"

using namespace mft;
using namespace mft::rawlog;

namespace {

const std::string kSchema1File = std::string(MFT_TEST_DATA_DIR) + "/rawlog/schema1.rawlog";

std::vector<Message> readAll(RawlogReader& r) {
  MessageAssembler a(r.metadata().time_base_unix_ns);
  std::vector<Message> out;
  mrpt::obs::CObservation::Ptr obs;
  Message m;
  std::int64_t t;
  while (r.next(&obs))
    if (a.add(*obs, &m, &t)) out.push_back(m);
  EXPECT_EQ(a.incomplete(), 0u);
  EXPECT_EQ(a.unknown(), 0u);
  return out;
}

}  // namespace

TEST(RawlogVersions, Schema1RecordingReadsBackEveryMessageExactly) {
  RawlogReader r(kSchema1File);
  EXPECT_EQ(r.metadata().schema_version, 1);
  EXPECT_EQ(r.metadata().dds_naming, "ros2");
  EXPECT_EQ(r.metadata().scenario_name, "schema1-fixture");
  const auto got = readAll(r);
  EXPECT_EQ(r.end(), RawlogReader::End::Clean);
  const auto want = fixture::messages();
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i].index(), want[i].index()) << "message " << i;
    EXPECT_TRUE(got[i] == want[i]) << "message " << i << " (" << topicName(topicOf(want[i])) << ") differs";
  }
}
