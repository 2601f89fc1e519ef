#include "services/runtime/dds_participant.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

namespace mft::services {

using namespace eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

int checkedDomainId(long domain_id) {
  if (domain_id < 0 || domain_id > kMaxDomainId)
    throw DdsError("bad DDS domain id " + std::to_string(domain_id) + ": must be in [0, " +
                   std::to_string(kMaxDomainId) + "]");
  return static_cast<int>(domain_id);
}

namespace {
// Loading the same profile file twice in one process makes Fast DDS report duplicate profiles.
void loadProfilesOnce(const std::string& file) {
  static std::mutex mutex;
  static std::set<std::string> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  if (loaded.count(file)) return;
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw DdsError("the DDS profile file " + file + " is a directory");
  if (!std::ifstream(file).good()) throw DdsError("cannot open the DDS profile file " + file);
  if (DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK)
    throw DdsError("the DDS profile file " + file + " could not be loaded (malformed XML?)");
  loaded.insert(file);
}
}  // namespace

DdsParticipant::DdsParticipant(int domain_id, const std::string& profiles_file, const std::string& name,
                               const SecurityOptions& security, const ReceiveTuning& receive)
    : domain_id_(checkedDomainId(domain_id)) {
  loadProfilesOnce(profiles_file);
  auto* factory = DomainParticipantFactory::get_instance();
  DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile("mft_participant", qos) != ReturnCode_t::RETCODE_OK)
    throw DdsError(profiles_file + ": no participant profile 'mft_participant'");
  qos.name(name);
  applyReceiveTuning(receive, &qos);
  applySecurity(security, &qos);
  participant_ = factory->create_participant(domain_id_, qos);
  if (!participant_)
    throw DdsError("cannot create a DDS participant on domain " + std::to_string(domain_id_) +
                   (security.enabled() ? " with the identity '" + security.identity + "' of " + security.dir +
                                             " (certificate, permissions or governance refused; see the SECURITY log lines)"
                                       : std::string()));
  publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (!publisher_ || !subscriber_) throw DdsError("cannot create the DDS publisher/subscriber");
}

DdsParticipant::~DdsParticipant() {
  if (!participant_) return;
  participant_->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

Topic* DdsParticipant::topic(const std::string& topic_name, TopicDataType* type) {
  auto it = topics_.find(topic_name);
  if (it != topics_.end()) return it->second;
  TypeSupport support(type);
  const std::string type_name = support.get_type_name();
  if (!types_.count(type_name)) {
    if (support.register_type(participant_) != ReturnCode_t::RETCODE_OK)
      throw DdsError("cannot register the DDS type " + type_name);
    types_.emplace(type_name, support);
  }
  Topic* t = participant_->create_topic(topic_name, type_name, TOPIC_QOS_DEFAULT);
  if (!t) throw DdsError("cannot create the DDS topic " + topic_name);
  topics_[topic_name] = t;
  return t;
}

}  // namespace mft::services
