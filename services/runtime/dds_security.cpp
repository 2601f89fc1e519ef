#include "services/runtime/dds_security.hpp"

#include <filesystem>

#include "services/runtime/dds_participant.hpp"

namespace mft::services {

std::string securityIdentity(const std::string& service) {
  return service.rfind("mft-", 0) == 0 ? service.substr(4) : service;
}

void applySecurity(const SecurityOptions& security, eprosima::fastdds::dds::DomainParticipantQos* qos) {
  if (!security.enabled()) return;
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::absolute(security.dir, ec);
  if (ec || !fs::is_directory(dir))
    throw DdsError("--secure: " + security.dir + " is not a directory (make one with scripts/make-security.sh DIR)");
  const std::string id = security.identity;
  // Fast DDS 2.9 accepts only file:// URIs with an absolute path (docs/reference/dds.md#security, trap 1).
  auto uri = [&](const std::string& file) {
    const fs::path p = dir / file;
    if (!fs::is_regular_file(p))
      throw DdsError("--secure: " + p.string() + " is missing (identity '" + id + "'; made by scripts/make-security.sh)");
    return "file://" + p.string();
  };
  auto& props = qos->properties().properties();
  props.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri("ca.pem"));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri(id + ".pem"));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri(id + ".key"));
  props.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri("ca.pem"));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri("governance.p7s"));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", uri("permissions_" + id + ".p7s"));
  props.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace mft::services
