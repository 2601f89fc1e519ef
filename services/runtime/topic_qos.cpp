#include "services/runtime/topic_qos.hpp"

#include "mft_topic_table.hpp"
#include "services/runtime/dds_participant.hpp"

namespace mft::services {
namespace {

std::string profileOf(std::string_view topic, bool lockstep, bool writer) {
  const int row = msg::topicIndex(topic);
  if (row < 0) throw DdsError("no topic " + std::string(topic) + " in the registry (idl/topics.yaml)");
  switch (msg::kTopics[static_cast<std::size_t>(row)].qos) {
    case msg::TopicQos::Chain:
      if (lockstep) return writer ? kLockstepWriterProfile : kLockstepReaderProfile;
      return writer ? kRealtimeWriterProfile : kRealtimeReaderProfile;
    case msg::TopicQos::Event: return writer ? "verdict_writer" : "event_reader";
    case msg::TopicQos::Progress: break;
  }
  return writer ? kLockstepWriterProfile : kLockstepReaderProfile;
}

}  // namespace

std::string serviceWriterProfile(std::string_view topic, bool lockstep) { return profileOf(topic, lockstep, true); }
std::string serviceReaderProfile(std::string_view topic, bool lockstep) { return profileOf(topic, lockstep, false); }

}  // namespace mft::services
