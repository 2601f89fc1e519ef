#pragma once
// The DDS side of every mft-wbc service: one participant built from the project's QoS profile file
// (config/dds_profiles.xml), loopback UDP only, and typed topic writers/readers created from named profiles.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "services/runtime/chain_channel.hpp"
#include "services/runtime/dds_security.hpp"
#include "services/runtime/polling_udp_transport.hpp"

namespace mft::services {

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Highest domain id usable with the default UDP port mapping of Fast DDS (PB 7400 + DG 250 * domain < 65536).
constexpr int kMaxDomainId = 232;

// The QoS profiles of the chain (a chain topic's in topic_qos.hpp); the chain channel carries only the topics
// written and read with these.
inline constexpr const char* kLockstepWriterProfile = "lockstep_writer";
inline constexpr const char* kLockstepReaderProfile = "lockstep_reader";
inline constexpr const char* kRealtimeWriterProfile = "control_writer";
inline constexpr const char* kRealtimeReaderProfile = "control_reader";
inline bool isChainWriterProfile(const std::string& p) {
  return p == kLockstepWriterProfile || p == kRealtimeWriterProfile;
}
inline bool isChainReaderProfile(const std::string& p) {
  return p == kLockstepReaderProfile || p == kRealtimeReaderProfile;
}

// Validates a domain id, throwing DdsError with a message that names the valid range.
int checkedDomainId(long domain_id);

// `--check-config`: loads `profiles_file` with Fast DDS's own XML loader and checks that it defines the
// participant profile "mft_participant" and every data_writer/data_reader profile the services use.
// Returns "" when it is usable, else one line naming the file and what Fast DDS refused (its XML parser's
// messages, which name the element). Creates no participant.
std::string checkProfilesFile(const std::string& profiles_file);

// What a participant tells the others in discovery, and whether it keeps what it hears of them. The defaults
// change nothing: a participant without them announces and listens exactly as before.
struct DiscoveryOptions {
  // The names of the stack's participants, comma-separated (the supervisor's --stack-services), announced in this
  // participant's user data: a peer learns from any one member which services the stack has, including those it
  // has not discovered yet (mft-cmd waits for every reader of its request, docs/guide/operator-commands.md).
  std::string stack_services;
  // Keep the list of the participants discovered (discoveredParticipants()): a participant listener that runs on
  // Fast DDS's discovery thread only. Tools (mft-cmd) turn it on; the services do not.
  bool keep_participants = false;
};

// A participant seen in discovery.
struct DiscoveredParticipant {
  std::string name;                             // its qos.name ("mft-record"); empty if it gave none
  std::array<std::uint8_t, 12> guid_prefix{};   // the first 12 bytes of the GUID of each of its endpoints
  std::vector<std::string> stack_services;      // what it announced (DiscoveryOptions), empty if nothing
  bool present = true;                          // false once it left or its lease expired
};

class ParticipantDiscovery;

class DdsParticipant {
 public:
  // Loads `profiles_file` (throws if it is missing or malformed) and creates a participant with the
  // "mft_participant" profile on `domain_id`. `name` identifies the service in discovery. With `security`
  // enabled the participant authenticates with that identity (docs/guide/security.md).
  // `receive` tunes the receive path (socket buffer, polling; polling_udp_transport.hpp).
  // `discovery`: what it announces and whether it keeps the participants it discovers (DiscoveryOptions).
  DdsParticipant(int domain_id, const std::string& profiles_file, const std::string& name,
                 const SecurityOptions& security = {}, const ReceiveTuning& receive = {},
                 const DiscoveryOptions& discovery = {});
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  // Registers the type on first use and returns the topic (one per name).
  eprosima::fastdds::dds::Topic* topic(const std::string& topic_name, eprosima::fastdds::dds::TopicDataType* type);

  eprosima::fastdds::dds::DomainParticipant* get() const { return participant_; }
  eprosima::fastdds::dds::Publisher* publisher() const { return publisher_; }
  eprosima::fastdds::dds::Subscriber* subscriber() const { return subscriber_; }
  int domainId() const { return domain_id_; }
  // With DiscoveryOptions::keep_participants: every participant discovered since this one was created (a copy,
  // taken under the listener's lock), in the order of discovery; empty otherwise.
  std::vector<DiscoveredParticipant> discoveredParticipants() const;
  // Chain services only: the shared-memory channel their chain topics travel by (chain_channel.hpp).
  // TopicWriter/TopicReader with the chain's profiles (lockstep or realtime) use it when it is open.
  void openChainChannel(const std::string& name) { chain_channel_ = std::make_unique<ChainChannel>(name); }
  ChainChannel* chainChannel() const { return chain_channel_.get(); }

 private:
  int domain_id_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::map<std::string, eprosima::fastdds::dds::TypeSupport> types_;
  std::unique_ptr<ChainChannel> chain_channel_;
  std::unique_ptr<ParticipantDiscovery> discovery_;  // with keep_participants only
};

}  // namespace mft::services
