#pragma once
// Pushes from the Disturbance topic (mft-cmd, docs/guide/operator-commands.md): each request is checked on arrival
// (chain/input_guard.hpp) and answered on CommandVerdict: rejected with the reason, or scheduled; once the
// simulator applies it, applied with the time and tick of the physics step that carried it. Fixed capacity:
// the loop never allocates; a request beyond it is rejected.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "chain/sim_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "common/json_writer.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/sim/command_link.hpp"

namespace mft::services {

class TopicPushes {
 public:
  // Shares `link`'s mutex (and reads the tick it published last for the verdicts).
  TopicPushes(ServiceContext& ctx, CommandLink& link, double max_push_Ns, double control_period_s);

  // Before the step: hands the requests accepted since the last step to the simulator.
  void scheduleInto(chain::SimNode& node);
  // After the step of tick k: the verdict "applied" for each request the step carried.
  void reportApplied(const chain::SimNode& node, std::uint64_t k);
  // disturbances_received, disturbances_applied, disturbances_rejected, as fields of the summary being written.
  void writeCounts(config::JsonWriter& w) const;
  // The array [[impulse N s, time s, tick], ...].
  void writeApplied(config::JsonWriter& w) const;

 private:
  void onRequest(const msg::Disturbance& m);

  struct Slot {
    std::uint64_t id = 0, seq = 0;  // ImpulseSpec::id (1, 2, ...) -> the request's seq
  };
  CommandLink& link_;
  double max_push_Ns_, control_period_s_;
  VerdictPublisher verdicts_;
  std::array<Slot, 64> slots_{};
  std::vector<sim::ImpulseSpec> pending_;
  std::vector<std::array<double, 3>> applied_;
  std::uint64_t next_id_ = 1, received_ = 0, applied_count_ = 0, rejected_ = 0;
  TopicReader<msg::Disturbance, msg::DisturbancePubSubType> reader_;
};

}  // namespace mft::services
