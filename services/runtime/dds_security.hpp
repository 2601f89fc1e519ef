#pragma once
// DDS Security (PKI-DH authentication, Access-Permissions, AES-GCM-GMAC) for one participant: the dds.sec.*
// properties of an identity in a directory made by scripts/make-security.sh (docs/guide/security.md). An empty
// directory means an unsecured participant, exactly as before.
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include <string>

namespace mft::services {

struct SecurityOptions {
  std::string dir;       // made by scripts/make-security.sh; empty: no security
  std::string identity;  // sim, estimator, planner, wbc, record, cmd: <identity>.pem/.key, permissions_<identity>.p7s
  bool enabled() const { return !dir.empty(); }
};

// The identity of a service: "mft-sim" -> "sim", "mft-record" -> "record"; other names unchanged.
std::string securityIdentity(const std::string& service);

// Checks that every file of the identity exists (throws DdsError naming the missing one) and adds the
// dds.sec.* properties to `qos`. Does nothing when `security` is not enabled.
void applySecurity(const SecurityOptions& security, eprosima::fastdds::dds::DomainParticipantQos* qos);

}  // namespace mft::services
