// mft-planner: the planner stage of the chain (chain/planner_node.hpp) as a service: RobotState(k) -> the paper's
// motion planner -> Reference(k). Operator commands come from the scenario (at simulated times) and from the
// OperatorCommand topic (mft-cmd, judged and answered in operator_inbox.hpp); a rejected command is reported and
// the last valid one stays in force. Live changes (mft-cmd --set planner.<key>=<value>) apply at a tick boundary.
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "chain/planner_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "services/planner/operator_inbox.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-planner", "Motion planner service: RobotState (+ OperatorCommand) -> Reference.");
  services::ServiceContext::declareOptions(cli);
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  services::ServiceContext ctx("mft-planner", cli);
  std::string config_text;  // the base of live changes (docs/live-tuning.md)
  std::unique_ptr<chain::PlannerNode> node;
  try {
    const auto config = planner::loadPlannerConfig(ctx.configFile("planner.yaml"));
    config_text = services::configTextInForce(ctx.configFile("planner.yaml"));
    node = std::make_unique<chain::PlannerNode>(config, ctx.robot(), ctx.scenario());
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();

  std::mutex mutex;  // the two readers' callbacks may run on different DDS threads
  model::RobotStateEstimate state;
  std::uint64_t scenario_rejected = 0;
  services::TickJoin join("mft-planner");
  services::HopTrace hops("mft-planner", {"state_in", "write", "written"});
  msg::Reference out_msg;
  services::LatencyStats update_us;
  services::OperatorInbox inbox(ctx.participant());
  // Live tuning: judged off the loop by planner.yaml's strict loader, applied at the tick boundary below (after
  // the operator commands of the tick, before its plan).
  using Tuning = services::LiveTuning<planner::PlannerTuning>;
  Tuning tuning(ctx.participant(), "mft-planner", msg::CONFIG_TARGET_PLANNER, msg::COMMAND_SOURCE_PLANNER,
                ctx.lockstep(), services::tuningStatusFile(cli.get("summary")), config_text,
                [](const std::string& text, const std::string& key, const std::string& value) {
                  auto o = planner::applyPlannerOverride(text, "planner.yaml (live change)", key, value);
                  return Tuning::Judged{planner::tuningOf(o.config), std::move(o.yaml_text), std::move(o.value),
                                        std::move(o.previous)};
                });
  auto report_scenario_command = [&](const planner::OperatorCommand& cmd, const planner::CommandResult& result) {
    if (!result.accepted) {
      ++scenario_rejected;
      std::fprintf(stderr, "mft-planner: scenario command rejected: %s\n", result.reason.c_str());
      return;
    }
    std::printf("mft-planner: scenario command: mode %d, height %.3f m, speed %.3f m/s\n", static_cast<int>(cmd.mode),
                cmd.z_cmd, cmd.v_cmd);
    std::fflush(stdout);
  };

  services::TopicWriter<msg::Reference, msg::ReferencePubSubType> writer(ctx.participant(), "Reference",
                                                                         ctx.chainWriterProfile());
  services::TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader(
      ctx.participant(), "RobotState", ctx.chainReaderProfile(), [&](const msg::RobotState& m) {
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        bool new_clock = false;  // an implausible state: the last good one stays, the real sample still comes
        if (!join.accept(services::validInput(m), "RobotState", m.tick()) || !join.admit(m.tick(), &new_clock)) return;
        if (new_clock) node->restart();  // a new world: the scenario's commands replay, the plan starts afresh
        const auto action = join.decide(m.tick(), true, true);
        if (action == services::TickJoin::Action::Resend) writer.write(out_msg);
        if (action != services::TickJoin::Action::Compute) return;
        const auto t0 = Clock::now();
        services::fromMsg(m, &state);
        node->applyScenarioCommands(state.time_s, report_scenario_command);
        inbox.applyPending(node->planner(), m.tick(), m.stamp_ns(), state.time_s);  // the operator's last word
        tuning.applyDue(m.tick(), state.time_s, m.stamp_ns(),
                        [&](const planner::PlannerTuning& t) { node->planner().setTuning(t); });
        const wbc::WbcReference& reference = node->plan(state);
        services::toMsg(node->output(), reference, &out_msg);
        out_msg.tick(m.tick());
        out_msg.stamp_ns(m.stamp_ns());
        update_us.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
        hops.mark(1, m.tick());
        writer.write(out_msg);
        hops.mark(2, m.tick());
        join.answered(m.tick());
      });
  services::TopicReader<msg::OperatorCommand, msg::OperatorCommandPubSubType> command_reader(
      ctx.participant(), "OperatorCommand", "event_reader", [&](const msg::OperatorCommand& m) {
        std::lock_guard<std::mutex> lock(mutex);
        inbox.receive(m, node->planner().limits(), join.lastTick());
      });

  services::announceReady("mft-planner");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  config::JsonWriter w;
  w.beginObject().field("service", "mft-planner").field("ticks", join.ticks()).field("last_tick", join.lastTick());
  w.field("steps", node->output().step_index).field("rejected_commands", scenario_rejected + inbox.rejected());
  w.key("operator_commands");
  inbox.writeCounts(w);
  join.writeCounts(w);
  services::writeDeadlineFields(w, state_reader.deadlineCounts());
  w.key("update_time_us").raw(update_us.json());
  w.key("live_changes").raw(tuning.summaryJson());
  ctx.writeSummary(w.endObject().str());
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-planner", [&] { return toolMain(argc, argv); });
}
