// A service's QoS profiles come from the topic registry (services/runtime/topic_qos.hpp): each qos class maps to
// the profiles of config/dds_profiles.xml by loop mode, every topic's profiles exist in that file, the chain's
// topics get the profiles the chain channel carries, and a topic the registry does not list is refused.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "mft_topic_table.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_qos.hpp"

using namespace mft::services;

TEST(TopicQos, EachClassMapsToItsProfilesByMode) {
  EXPECT_EQ(serviceWriterProfile("SensorData", true), "lockstep_writer");
  EXPECT_EQ(serviceWriterProfile("SensorData", false), "control_writer");
  EXPECT_EQ(serviceReaderProfile("JointCommand", true), "lockstep_reader");
  EXPECT_EQ(serviceReaderProfile("JointCommand", false), "control_reader");
  EXPECT_EQ(serviceReaderProfile("OperatorCommand", false), "event_reader");
  EXPECT_EQ(serviceWriterProfile("CommandVerdict", true), "verdict_writer");
  EXPECT_EQ(serviceWriterProfile("ConfigChange", false), "verdict_writer");
  EXPECT_EQ(serviceReaderProfile("RecorderProgress", true), "lockstep_reader");
  EXPECT_EQ(serviceReaderProfile("RecorderProgress", false), "lockstep_reader");
}

TEST(TopicQos, EveryTopicsProfilesAreDefinedAndTheChainsRideTheChannel) {
  std::ifstream in(MFT_DDS_PROFILES);
  ASSERT_TRUE(in) << MFT_DDS_PROFILES;
  std::stringstream xml;
  xml << in.rdbuf();
  for (const auto& t : mft::msg::kTopics) {
    for (const bool lockstep : {true, false}) {
      const std::string writer = serviceWriterProfile(t.type, lockstep);
      const std::string reader = serviceReaderProfile(t.type, lockstep);
      EXPECT_NE(xml.str().find("profile_name=\"" + writer + "\""), std::string::npos) << t.type << " " << writer;
      EXPECT_NE(xml.str().find("profile_name=\"" + reader + "\""), std::string::npos) << t.type << " " << reader;
      if (t.chain_slot >= 0) {
        EXPECT_TRUE(isChainWriterProfile(writer)) << t.type;
        EXPECT_TRUE(isChainReaderProfile(reader)) << t.type;
      }
    }
  }
}

TEST(TopicQos, AnUnknownTopicIsRefusedWithItsName) {
  try {
    serviceWriterProfile("NoSuchTopic", true);
    FAIL() << "no error";
  } catch (const DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("NoSuchTopic"), std::string::npos) << e.what();
  }
  EXPECT_THROW(serviceReaderProfile("sensor_data", false), DdsError);
}
