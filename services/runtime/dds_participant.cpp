#include "services/runtime/dds_participant.hpp"
#include "services/runtime/topic_names.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

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

namespace {
// Collects what Fast DDS logs while it parses a profile file: its XML parser names the refused element
// only in its log, not in the return code.
class CollectingLogConsumer : public eprosima::fastdds::dds::LogConsumer {
 public:
  explicit CollectingLogConsumer(std::vector<std::string>* lines) : lines_(lines) {}
  void Consume(const eprosima::fastdds::dds::Log::Entry& entry) override {
    if (entry.kind == eprosima::fastdds::dds::Log::Kind::Error) lines_->push_back(entry.message);
  }

 private:
  std::vector<std::string>* lines_;
};
}  // namespace

std::string checkProfilesFile(const std::string& profiles_file) {
  using eprosima::fastdds::dds::Log;
  if (!std::ifstream(profiles_file).good()) return profiles_file + ": cannot open the DDS profile file";
  std::vector<std::string> errors;
  Log::ClearConsumers();
  Log::RegisterConsumer(std::make_unique<CollectingLogConsumer>(&errors));
  auto* factory = DomainParticipantFactory::get_instance();
  const bool loaded = factory->load_XML_profiles_file(profiles_file) == ReturnCode_t::RETCODE_OK;
  Log::Flush();
  Log::ClearConsumers();  // the collector points at a local; nothing more is logged in a check
  std::string detail;
  for (const auto& e : errors) detail += (detail.empty() ? "" : "; ") + e;
  if (!loaded || !errors.empty())
    return profiles_file + ": Fast DDS refused the profile file" + (detail.empty() ? "" : ": " + detail);
  DomainParticipantQos participant_qos;
  if (factory->get_participant_qos_from_profile("mft_participant", participant_qos) != ReturnCode_t::RETCODE_OK)
    return profiles_file + ": no participant profile 'mft_participant'";
  using eprosima::fastrtps::xmlparser::XMLP_ret;
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  for (const char* name : {"control_writer", "reliable_writer", "lockstep_writer", "event_writer"}) {
    eprosima::fastrtps::PublisherAttributes attributes;
    if (XMLProfileManager::fillPublisherAttributes(name, attributes, false) != XMLP_ret::XML_OK)
      return profiles_file + ": no data_writer profile '" + name + "'";
  }
  for (const char* name : {"control_reader", "reliable_reader", "lockstep_reader", "event_reader"}) {
    eprosima::fastrtps::SubscriberAttributes attributes;
    if (XMLProfileManager::fillSubscriberAttributes(name, attributes, false) != XMLP_ret::XML_OK)
      return profiles_file + ": no data_reader profile '" + name + "'";
  }
  return "";
}

namespace {
// The stack's services in a participant's user data: this prefix, then the names, comma-separated.
constexpr const char kStackServicesTag[] = "mft-stack-services=";

std::vector<std::string> stackServicesOf(const std::vector<eprosima::fastrtps::rtps::octet>& user_data) {
  const std::string text(user_data.begin(), user_data.end());
  std::vector<std::string> names;
  if (text.rfind(kStackServicesTag, 0) != 0) return names;
  for (std::size_t at = sizeof kStackServicesTag - 1; at <= text.size();) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    if (comma > at) names.push_back(text.substr(at, comma - at));
    at = comma + 1;
  }
  return names;
}
}  // namespace

// Keeps the participants discovered, on Fast DDS's discovery thread (never a service's tick path).
class ParticipantDiscovery : public DomainParticipantListener {
 public:
  void on_participant_discovery(DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using Info = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
    DiscoveredParticipant p;
    std::memcpy(p.guid_prefix.data(), info.info.m_guid.guidPrefix.value, p.guid_prefix.size());
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = std::find_if(seen_.begin(), seen_.end(), [&](const auto& s) { return s.guid_prefix == p.guid_prefix; });
    if (info.status == Info::REMOVED_PARTICIPANT || info.status == Info::DROPPED_PARTICIPANT) {
      if (it != seen_.end()) it->present = false;
      return;
    }
    p.name = info.info.m_participantName.c_str();
    p.stack_services = stackServicesOf(info.info.m_userData.data_vec());
    if (it == seen_.end()) seen_.push_back(std::move(p));
    else *it = std::move(p);  // discovered again (its lease had expired), or its QoS changed
  }
  std::vector<DiscoveredParticipant> participants() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<DiscoveredParticipant> seen_;
};

DdsParticipant::DdsParticipant(int domain_id, const std::string& profiles_file, const std::string& name,
                               const SecurityOptions& security, const ReceiveTuning& receive,
                               const DiscoveryOptions& discovery)
    : domain_id_(checkedDomainId(domain_id)) {
  loadProfilesOnce(profiles_file);
  auto* factory = DomainParticipantFactory::get_instance();
  DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile("mft_participant", qos) != ReturnCode_t::RETCODE_OK)
    throw DdsError(profiles_file + ": no participant profile 'mft_participant'");
  qos.name(name);
  applyReceiveTuning(receive, &qos);
  applySecurity(security, &qos);
  if (!discovery.stack_services.empty()) {
    const std::string text = kStackServicesTag + discovery.stack_services;
    qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(text.begin(), text.end()));
  }
  if (discovery.keep_participants) {  // the listener from the start: the first peers answer within milliseconds
    discovery_ = std::make_unique<ParticipantDiscovery>();
    participant_ = factory->create_participant(domain_id_, qos, discovery_.get(), StatusMask::none());
  } else {
    participant_ = factory->create_participant(domain_id_, qos);
  }
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
  if (discovery_) participant_->set_listener(nullptr);
  participant_->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

std::vector<DiscoveredParticipant> DdsParticipant::discoveredParticipants() const {
  return discovery_ ? discovery_->participants() : std::vector<DiscoveredParticipant>();
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
  const std::string dds_name = ddsTopicName(topic_name);
  Topic* t = participant_->create_topic(dds_name, type_name, TOPIC_QOS_DEFAULT);
  if (!t) throw DdsError("cannot create the DDS topic " + dds_name);
  topics_[topic_name] = t;
  return t;
}

}  // namespace mft::services
