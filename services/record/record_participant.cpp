#include "services/record/record_participant.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "services/runtime/dds_security.hpp"
#include "services/runtime/topic_names.hpp"

namespace mft::services {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

RecordParticipant::RecordParticipant(int domain, const std::string& profiles_file, const ReceiveTuning& tuning,
                                     const SecurityOptions& security) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  if (factory->load_XML_profiles_file(profiles_file) != ReturnCode_t::RETCODE_OK)
    throw DdsError("the DDS profile file " + profiles_file + " could not be loaded");
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile("mft_participant", qos) != ReturnCode_t::RETCODE_OK)
    throw DdsError(profiles_file + ": no participant profile 'mft_participant'");
  qos.name("mft-record");
  applyReceiveTuning(tuning, &qos);
  applySecurity(security, &qos);
  participant_ = factory->create_participant(domain, qos);
  if (!participant_) throw DdsError("cannot create a DDS participant on domain " + std::to_string(domain));
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!subscriber_) throw DdsError("cannot create the DDS subscriber");
}

RecordParticipant::~RecordParticipant() {
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

void RecordParticipant::enableProgress() {
  dds::TypeSupport type(new msg::RecorderProgressPubSubType());
  type.register_type(participant_);
  auto* topic = participant_->create_topic(ddsTopicName("RecorderProgress"), type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (!topic || !publisher_) throw DdsError("cannot create the RecorderProgress topic");
  progress_writer_ = publisher_->create_datawriter_with_profile(topic, "lockstep_writer");  // best effort: re-sent every 50 ms at worst
  if (!progress_writer_) throw DdsError("cannot create a writer on RecorderProgress (permissions?)");
}

void RecordParticipant::publishProgress(std::uint64_t tick, std::uint64_t all_topics_tick, std::uint64_t received) {
  if (!progress_writer_) return;
  progress_.tick(tick);
  progress_.all_topics_tick(all_topics_tick);
  progress_.received(received);
  progress_writer_->write(&progress_);
}

}  // namespace mft::services
