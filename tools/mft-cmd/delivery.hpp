#pragma once
// Which of the stack's services a request of mft-cmd reached (docs/guide/operator-commands.md, "Every reader gets it").
// The services that must have it are those whose identity reads the topic in the registry (idl/topics.yaml: its
// readers, and the recorder when it is recorded), among the participants discovered on the domain and the stack's
// services they announce (the supervisor's --stack-services). A service got the request when each of its
// participant's matched readers acknowledged the sample; one that never matched or never acknowledged within the
// bound is named, with why.
#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "common/json_writer.hpp"
#include "services/runtime/chain_channel.hpp"
#include "services/runtime/dds_participant.hpp"

namespace mft::cmd {

// One of mft-cmd's writers as the delivery check sees it: its matched readers and the wait for their acknowledgements.
class AckSource {
 public:
  virtual ~AckSource() = default;
  virtual std::vector<services::ChainChannel::EndpointId> matchedReaders() const = 0;
  virtual bool waitForAcknowledgments(std::chrono::milliseconds timeout) = 0;
};

template <class Writer>
class WriterAcks : public AckSource {
 public:
  explicit WriterAcks(Writer& writer) : writer_(writer) {}
  std::vector<services::ChainChannel::EndpointId> matchedReaders() const override { return writer_.matchedReaders(); }
  bool waitForAcknowledgments(std::chrono::milliseconds timeout) override {
    return writer_.waitForAcknowledgments(timeout);
  }

 private:
  Writer& writer_;
};

// A service that should have had the request and did not, and why.
struct Missed {
  std::string service, reason;
};

// What one written sample reached.
struct Reach {
  std::vector<std::string> delivered;  // services whose readers acknowledged it
  std::vector<Missed> missed;
  bool known = false;  // false until the check ran (no stack: nothing to say)

  bool complete() const { return missed.empty(); }
  bool missedBy(const std::string& service) const;
  // A verdict of `service` proves it received the request, acknowledged or not.
  void confirmedBy(const std::string& service);
  // "mft-record (not discovered on the domain: …), so the recording lacks it", several joined with "; "
  std::string missedText() const;
  // "acknowledged by mft-planner, mft-record", or "NOT acknowledged by every reader: " and missedText()
  std::string ackText() const;
  // "delivered_to": [names], "not_delivered_to": [{"service", "reason"}]
  void writeJson(config::JsonWriter& w) const;
};

// Waits until every service that reads `topic` has acknowledged the sample on each of `writers` (written already),
// and the `answerers` (the services that answer it) have been discovered, or until `deadline`; one Reach per writer.
std::vector<Reach> awaitDelivery(const services::DdsParticipant& participant, std::string_view topic,
                                 const std::vector<AckSource*>& writers, const std::vector<std::string>& answerers,
                                 std::chrono::steady_clock::time_point deadline);

}  // namespace mft::cmd
