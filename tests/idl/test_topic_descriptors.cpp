// The generated topic descriptors (idl/topics.yaml through idl/gen_topics.py into mft_topics.hpp): one row per
// message, the chain's slots numbered in row order, field lists that match the visitors, and dispatch by name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <type_traits>

#include "idl/msg_pubsub.hpp"

using namespace mft::msg;

TEST(TopicDescriptors, OneRowPerMessageInTheIdlsOrder) {
  int n = 0;
#define MFT_COUNT(Name) ++n;
  MFT_MSG_TYPES(MFT_COUNT)
#undef MFT_COUNT
  EXPECT_EQ(static_cast<int>(kTopics.size()), n);
  EXPECT_EQ(topicIndex("SensorData"), 0);
  EXPECT_EQ(topicIndex("ConfigChange"), static_cast<int>(kTopics.size()) - 1);
  EXPECT_EQ(topicIndex("NoSuchTopic"), -1);
  EXPECT_EQ(topicInfo<JointCommand>().wire, "rt/mft/joint_command");
  EXPECT_EQ(topicInfo<CommandVerdict>().qos, TopicQos::Event);
}

TEST(TopicDescriptors, ChainSlotsAreNumberedInRowOrder) {
  int next = 0;
  for (const auto& t : kTopics) {
    if (t.chain_slot >= 0) {
      EXPECT_EQ(t.chain_slot, next++) << t.type;
    }
  }
  EXPECT_EQ(next, kChainSlots);
  EXPECT_EQ(topicInfo<SensorData>().chain_slot, 0);
  EXPECT_EQ(topicInfo<WbcDiagnostics>().chain_slot, 5);
  EXPECT_EQ(topicInfo<OperatorCommand>().chain_slot, -1);
}

template <class M>
int visitedFields() {
  M m;
  int n = 0;
  visitFields(m, [&](const char* name, auto&) {
    EXPECT_EQ(std::string(name), std::string(MessageFields<M>::list[static_cast<std::size_t>(n)].name));
    ++n;
  });
  return n;
}

TEST(TopicDescriptors, FieldListsMatchTheVisitors) {
  forEachTopicType([](auto tag) {
    using M = typename decltype(tag)::type;
    EXPECT_EQ(visitedFields<M>(), static_cast<int>(MessageFields<M>::list.size()));
  });
  EXPECT_EQ(MessageFields<SensorData>::list[2].name, "actuated_pos");
  EXPECT_EQ(MessageFields<SensorData>::list[2].kind, FieldKind::F64);
  EXPECT_EQ(MessageFields<SensorData>::list[2].count, 4);
  EXPECT_EQ(MessageFields<CommandVerdict>::list[6].kind, FieldKind::Char);
  EXPECT_EQ(MessageFields<CommandVerdict>::list[6].count, 160);
}

TEST(TopicDescriptors, VisitorsReachTheFieldsAndBadValuesLeaveTheRange) {
  JointCommand c;
  visitFields(c, [](const char* name, auto& v) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::array<double, 4>>)
      if (std::string(name) == "tau") v[2] = 7.5;
  });
  EXPECT_EQ(c.tau()[2], 7.5);
  setBadValues(c);
  EXPECT_EQ(c.mode(), 99);
  Disturbance d;
  setBadValues(d);
  EXPECT_EQ(d.trigger(), 9);
  EXPECT_EQ(d.leg(), 9);
}

TEST(TopicDescriptors, DispatchByNameFindsTheTypeAndItsPubSubType) {
  std::string got;
  EXPECT_TRUE(withTopicType("Reference", [&](auto tag) {
    using M = typename decltype(tag)::type;
    got = typename PubSubOf<M>::type().getName();
  }));
  EXPECT_EQ(got, "mft::msg::dds_::Reference_");
  EXPECT_FALSE(withTopicType("Nothing", [](auto) {}));
}
