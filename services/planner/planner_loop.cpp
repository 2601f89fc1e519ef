#include "services/planner/planner_loop.hpp"

#include <chrono>
#include <cstdio>

#include "common/json_writer.hpp"
#include "common/strict_yaml.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"

namespace mft::services {

using Clock = std::chrono::steady_clock;

TunableNode<chain::PlannerNode> PlannerLoop::load(const ServiceContext& ctx, const CommandLine& cli) {
  try {
    const auto config = planner::loadPlannerConfig(ctx.configFile("planner.yaml"));
    return {std::make_unique<chain::PlannerNode>(config, ctx.robot(), ctx.scenario()),
            configTextInForce(ctx.configFile("planner.yaml"))};
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
}

// Live tuning: judged off the loop by planner.yaml's strict loader, applied at the tick boundary in answer()
// (after the operator commands of the tick, before its plan).
PlannerLoop::PlannerLoop(ServiceContext& ctx, const CommandLine& cli,
                         const TunableNode<chain::PlannerNode>& loaded)
    : ctx_(ctx),
      node_(*loaded.node),
      inbox_(ctx.participant()),
      tuning_(ctx.participant(), "mft-planner", msg::CONFIG_TARGET_PLANNER, msg::COMMAND_SOURCE_PLANNER,
              ctx.lockstep(), tuningStatusFile(cli.get("summary")), loaded.config_text,
              [](const std::string& text, const std::string& key, const std::string& value) {
                auto o = planner::applyPlannerOverride(text, "planner.yaml (live change)", key, value);
                return LiveTuning<planner::PlannerTuning>::Judged{planner::tuningOf(o.config), std::move(o.yaml_text),
                                                        std::move(o.value), std::move(o.previous)};
              }),
      writer_(ctx.writing("Reference")),
      state_reader_(ctx.reading("RobotState"),
                    [this](const msg::RobotState& m) { onState(m); }),
      command_reader_(ctx.reading("OperatorCommand"), [this](const msg::OperatorCommand& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        inbox_.receive(m, node_.planner().limits(), join_.lastTick());
      }) {}

void PlannerLoop::onState(const msg::RobotState& m) {
  hops_.mark(0, m.tick());
  std::lock_guard<std::mutex> lock(mutex_);
  bool new_clock = false;  // an implausible state: the last good one stays, the real sample still comes
  if (!join_.acceptTick(validInput(m), "RobotState", m.tick(), &new_clock)) return;
  if (new_clock) node_.restart();  // a new world: the scenario's commands replay, the plan starts afresh
  const auto action = join_.decide(m.tick(), true, true);
  if (action == TickJoin::Action::Resend) writer_.write(out_msg_);
  if (action == TickJoin::Action::Compute) answer(m);
}

void PlannerLoop::answer(const msg::RobotState& m) {
  const auto t0 = Clock::now();
  fromMsg(m, &state_);
  node_.applyScenarioCommands(state_.time_s, [this](const planner::OperatorCommand& cmd,
                                                    const planner::CommandResult& result) {
    reportScenarioCommand(cmd, result);
  });
  inbox_.applyPending(node_.planner(), m.tick(), m.stamp_ns(), state_.time_s);  // the operator's last word
  tuning_.applyDue(m.tick(), state_.time_s, m.stamp_ns(),
                   [&](const planner::PlannerTuning& t) { node_.planner().setTuning(t); });
  const wbc::WbcReference& reference = node_.plan(state_);
  toMsg(node_.output(), reference, &out_msg_);
  out_msg_.tick(m.tick());
  out_msg_.stamp_ns(m.stamp_ns());
  update_us_.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  hops_.mark(1, m.tick());
  writer_.write(out_msg_);
  hops_.mark(2, m.tick());
  join_.answered(m.tick());
}

void PlannerLoop::reportScenarioCommand(const planner::OperatorCommand& cmd, const planner::CommandResult& result) {
  if (!result.accepted) {
    ++scenario_rejected_;
    std::fprintf(stderr, "mft-planner: scenario command rejected: %s\n", result.reason.c_str());
    return;
  }
  std::printf("mft-planner: scenario command: mode %d, height %.3f m, speed %.3f m/s\n", static_cast<int>(cmd.mode),
              cmd.z_cmd, cmd.v_cmd);
  std::fflush(stdout);
}

std::string PlannerLoop::summaryJson() {
  std::lock_guard<std::mutex> lock(mutex_);
  config::JsonWriter w;
  w.beginObject().field("service", "mft-planner").field("ticks", join_.ticks()).field("last_tick", join_.lastTick());
  w.field("steps", node_.output().step_index).field("rejected_commands", scenario_rejected_ + inbox_.rejected());
  w.key("operator_commands");
  inbox_.writeCounts(w);
  join_.writeCounts(w);
  writeDeadlineFields(w, state_reader_.deadlineCounts());
  w.key("update_time_us").raw(update_us_.json());
  w.key("live_changes").raw(tuning_.summaryJson());
  return w.endObject().str();
}

}  // namespace mft::services
