#include "tools/mft-cmd/delivery.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <set>
#include <thread>

#include "mft_topic_table.hpp"
#include "services/runtime/dds_security.hpp"

namespace mft::cmd {

namespace {

using Prefix = std::array<std::uint8_t, 12>;
using Clock = std::chrono::steady_clock;
using Participants = std::vector<services::DiscoveredParticipant>;

Prefix prefixOf(const services::ChainChannel::EndpointId& id) {
  Prefix p{};
  std::memcpy(p.data(), id.data(), p.size());
  return p;
}

// One writer as the check follows it: the participants whose readers have acknowledged the sample.
struct Follow {
  AckSource* writer = nullptr;
  std::set<Prefix> confirmed;
  std::vector<services::ChainChannel::EndpointId> matched;  // at the last look
};

// Waits up to `slice` for the acknowledgements of the readers matched now. Fast DDS 2.9 tells whether all matched
// readers acknowledged, not which: those matched both before and after a successful wait did.
void look(Follow& f, std::chrono::milliseconds slice) {
  const auto before = f.writer->matchedReaders();
  const bool acked = f.writer->waitForAcknowledgments(slice);
  f.matched = f.writer->matchedReaders();
  if (!acked) return;
  for (const auto& id : before)
    if (std::find(f.matched.begin(), f.matched.end(), id) != f.matched.end()) f.confirmed.insert(prefixOf(id));
}

// The services that must get a sample of the topic: every service named by a participant (its own name, or the
// stack it announced) whose identity reads the topic.
std::set<std::string> requiredServices(const msg::TopicInfo& topic, const Participants& seen) {
  std::set<std::string> names;
  for (const auto& p : seen) {
    names.insert(p.stack_services.begin(), p.stack_services.end());
    if (!p.name.empty()) names.insert(p.name);
  }
  for (auto it = names.begin(); it != names.end();)
    it = msg::readBy(topic, services::securityIdentity(*it)) ? std::next(it) : names.erase(it);
  return names;
}

// Why `service` has not got the sample yet, "" when it has: every participant of that name on the domain has a
// matched reader that acknowledged it.
std::string whyNot(const std::string& service, const Follow& f, const Participants& seen) {
  bool present = false, lost = false;
  for (const auto& p : seen) {
    if (p.name != service) continue;
    if (!p.present) {
      lost = true;
      continue;
    }
    present = true;
    if (f.confirmed.count(p.guid_prefix)) continue;
    const bool matched =
        std::any_of(f.matched.begin(), f.matched.end(), [&](const auto& id) { return prefixOf(id) == p.guid_prefix; });
    return matched ? "its reader did not acknowledge" : "discovered, but no reader of it matched";
  }
  if (present) return "";
  return lost ? "gone from the domain before acknowledging: stopped, or silent past its lease"
              : "not discovered on the domain: stopped or not running?";
}

// Every matched reader's participant has been discovered: what it announced of the stack has been read.
bool allIdentified(const std::vector<Follow>& follows, const Participants& seen) {
  for (const auto& f : follows)
    for (const auto& id : f.matched)
      if (std::none_of(seen.begin(), seen.end(), [&](const auto& p) { return p.guid_prefix == prefixOf(id); }))
        return false;
  return true;
}

std::vector<Reach> reaches(const std::vector<Follow>& follows, const std::set<std::string>& required,
                           const Participants& seen) {
  std::vector<Reach> out;
  for (const auto& f : follows) {
    Reach r;
    r.known = true;
    for (const auto& service : required) {
      const std::string why = whyNot(service, f, seen);
      if (why.empty()) r.delivered.push_back(service);
      else r.missed.push_back({service, why});
    }
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace

bool Reach::missedBy(const std::string& service) const {
  return std::any_of(missed.begin(), missed.end(), [&](const Missed& m) { return m.service == service; });
}

void Reach::confirmedBy(const std::string& service) {
  if (!missedBy(service)) return;
  missed.erase(std::remove_if(missed.begin(), missed.end(), [&](const Missed& m) { return m.service == service; }),
               missed.end());
  delivered.push_back(service);
  std::sort(delivered.begin(), delivered.end());
}

std::string Reach::missedText() const {
  std::string text;
  for (const auto& m : missed)
    text += (text.empty() ? "" : "; ") + m.service + " (" + m.reason + ")" +
            (m.service == "mft-record" ? ", so the recording lacks it" : "");
  return text;
}

std::string Reach::ackText() const {
  if (!complete()) return "NOT acknowledged by every reader: " + missedText();
  std::string names;
  for (const auto& s : delivered) names += (names.empty() ? " by " : ", ") + s;
  return "acknowledged" + names;
}

void Reach::writeJson(config::JsonWriter& w) const {
  w.key("delivered_to").beginArray();
  for (const auto& s : delivered) w.value(s);
  w.endArray().key("not_delivered_to").beginArray();
  for (const auto& m : missed) w.beginObject().field("service", m.service).field("reason", m.reason).endObject();
  w.endArray();
}

// The stack's services announce the whole stack in their discovery data, and a participant's announcement
// (SPDP) is processed before any of its readers can match (their discovery, SEDP, runs over endpoints that the
// announcement creates). Fast DDS may still report the match before the participant, on another thread, so the
// loop also waits until every matched reader's participant is known. From then on the list of services that
// must have the sample is complete, including one not discovered yet (the recorder runs niced and may answer
// discovery last), and that one is waited for by name, up to the deadline: a condition, not a sleep. The recorder
// announces nothing itself, so the list counts as complete only once the answering service (started by the
// supervisor like every service) has been discovered: with only the recorder heard, the planner's or the WBC's
// acknowledgement would otherwise go unchecked. A stack
// started by hand, without the supervisor's --stack-services, announces nothing: then only the participants
// discovered before every one of them acknowledged are waited for.
std::vector<Reach> awaitDelivery(const services::DdsParticipant& participant, std::string_view topic,
                                 const std::vector<AckSource*>& writers, const std::vector<std::string>& answerers,
                                 Clock::time_point deadline) {
  const int row = msg::topicIndex(topic);
  const msg::TopicInfo& info = msg::kTopics[static_cast<std::size_t>(std::max(row, 0))];
  std::vector<Follow> follows(writers.size());
  for (std::size_t i = 0; i < writers.size(); ++i) follows[i].writer = writers[i];
  Participants seen;
  std::set<std::string> required;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    for (auto& f : follows) look(f, std::clamp(left, std::chrono::milliseconds(0), std::chrono::milliseconds(50)));
    seen = participant.discoveredParticipants();
    required = requiredServices(info, seen);
    bool done = row >= 0 && allIdentified(follows, seen);
    for (const auto& service : answerers)
      done = done && std::any_of(seen.begin(), seen.end(), [&](const auto& p) { return p.present && p.name == service; });
    for (const auto& f : follows)
      for (const auto& service : required) done = done && whyNot(service, f, seen).empty();
    if (done || Clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return reaches(follows, required, seen);
}

}  // namespace mft::cmd
