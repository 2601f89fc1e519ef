// mft-participants: which DDS participants are on a domain. Joins the domain with the project's participant
// profile (or a stack host's profile, --profiles), listens for participant discovery for a bounded time and
// prints what it discovered (name, GUID prefix, addresses, when), as text or --json. The supervisor runs it
// before it starts a stack, to refuse a domain that is already in use (docs/results/faults.md, "Bad input and misuse").
// Exit status: 0 (whatever it found), 2 on bad options or an unusable profile file, 3 when the participant
// cannot be created.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/rtps/common/Locator.h>
#include <fastrtps/utils/IPLocator.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/tool_io.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/process.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
using Clock = std::chrono::steady_clock;

struct Seen {
  std::string name, guid_prefix;
  std::set<std::string> addresses;
  double discovered_ms = 0.0;
  bool left = false;  // it announced its end (or its lease expired) while we listened
};

class DiscoveryListener : public fdds::DomainParticipantListener {
 public:
  explicit DiscoveryListener(Clock::time_point t0) : t0_(t0) {}

  void on_participant_discovery(fdds::DomainParticipant*, ParticipantDiscoveryInfo&& info) override {
    std::ostringstream guid;
    guid << info.info.m_guid.guidPrefix;
    std::lock_guard<std::mutex> lock(mutex_);
    if (info.status == ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
      Seen s;
      s.name = info.info.m_participantName.to_string();
      s.guid_prefix = guid.str();
      for (const auto& l : info.info.metatraffic_locators.unicast) s.addresses.insert(IPLocator::toIPv4string(l));
      for (const auto& l : info.info.default_locators.unicast) s.addresses.insert(IPLocator::toIPv4string(l));
      s.discovered_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0_).count();
      seen_.push_back(s);
      cv_.notify_all();
    } else if (info.status == ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
               info.status == ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
      for (auto& s : seen_)
        if (s.guid_prefix == guid.str()) s.left = true;
    }
  }

  // Waits until `deadline`, or until the first participant with `stop_at_first`.
  std::vector<Seen> wait(Clock::time_point deadline, bool stop_at_first) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, deadline, [&] { return stop_at_first && !seen_.empty(); });
    return seen_;
  }

 private:
  Clock::time_point t0_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Seen> seen_;
};

}  // namespace

int toolMain(int argc, char** argv) {
  mft::services::CommandLine cli(
      "mft-participants",
      "Lists the DDS participants on a domain: joins it with the project's participant profile, listens for\n"
      "participant discovery for --wait-ms and prints every participant it discovered (name, GUID prefix,\n"
      "addresses). The supervisor uses it to refuse a domain that is already in use.");
  cli.option("domain", "DDS domain id (0..232)", "", true);
  cli.option("profiles", "DDS QoS profile file (its participant profile mft_participant is used)",
             mft::config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES));
  cli.option("wait-ms", "how long to listen for participants [ms] (docs/results/faults.md: discovery on loopback took "
             "92-368 ms on a loaded 2-core VM)", "1000");
  cli.flag("stop-at-first", "return as soon as one participant is discovered");
  cli.flag("json", "print JSON");
  cli.parse(argc, argv);
  const int domain = static_cast<int>(cli.getInt("domain", 0, mft::services::kMaxDomainId));
  const double wait_ms = cli.getDouble("wait-ms", 0, 60000);
  const std::string profiles = cli.get("profiles");

  // Fast DDS's XML errors would otherwise be printed as coloured log lines; report them as one line.
  const std::string problem = mft::services::checkProfilesFile(profiles);
  if (!problem.empty()) cli.fail(problem);
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile("mft_participant", qos) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
    cli.fail(profiles + ": no participant profile 'mft_participant'");
  qos.name("mft-participants");
  const auto t0 = Clock::now();
  DiscoveryListener listener(t0);
  fdds::DomainParticipant* participant = factory->create_participant(domain, qos, &listener, fdds::StatusMask::none());
  if (!participant) {
    std::fprintf(stderr, "mft-participants: cannot create a DDS participant on domain %d\n", domain);
    return 3;
  }
  const auto deadline = t0 + std::chrono::microseconds(static_cast<long long>(wait_ms * 1000.0));
  const std::vector<Seen> seen = listener.wait(deadline, cli.isSet("stop-at-first"));
  const double listened_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  participant->set_listener(nullptr);
  factory->delete_participant(participant);

  if (cli.isSet("json")) {
    mft::config::JsonWriter w;
    w.beginObject().field("domain", domain).fixedField("wait_ms", wait_ms, 0).fixedField("listened_ms", listened_ms, 1);
    w.key("participants").beginArray();
    for (const Seen& p : seen) {
      w.beginObject().field("name", p.name).field("guid_prefix", p.guid_prefix).fixedField("discovered_ms", p.discovered_ms, 1);
      w.field("left", p.left).key("addresses").beginArray();
      for (const auto& address : p.addresses) w.value(address);
      w.endArray().endObject();
    }
    std::printf("%s\n", w.endArray().endObject().str().c_str());
  } else {
    std::printf("domain %d: %zu participant(s) in %.0f ms\n", domain, seen.size(), listened_ms);
    for (const Seen& s : seen) {
      std::string addresses;
      for (const auto& a : s.addresses) addresses += (addresses.empty() ? "" : ",") + a;
      std::printf("  %-20s %s  at %s  (after %.1f ms%s)\n", s.name.empty() ? "(no name)" : s.name.c_str(),
                  s.guid_prefix.c_str(), addresses.c_str(), s.discovered_ms, s.left ? ", left since" : "");
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-participants", [&] { return toolMain(argc, argv); });
}
