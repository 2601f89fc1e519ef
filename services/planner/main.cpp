// mft-planner: RobotState(k) -> the paper's motion planner -> Reference(k). Operator commands come from the
// scenario (at simulated times) and from the OperatorCommand topic (mft-cmd); a rejected command is reported
// and the last valid one stays in force. Every OperatorCommand is answered on CommandVerdict: rejected with the
// reason on arrival, or scheduled on arrival and applied at the next tick the planner answers (before that
// tick's plan, so it acts from a well-defined tick, named in the verdict; docs/operator-commands.md).
#include <array>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "model/config/strict_yaml.hpp"
#include "planner/motion_planner.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/tick_gate.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

namespace {
planner::LocomotionMode toPlannerMode(services::LocomotionMode m) {
  switch (m) {
    case services::LocomotionMode::Stand: return planner::LocomotionMode::Stand;
    case services::LocomotionMode::StepInPlace: return planner::LocomotionMode::StepInPlace;
    case services::LocomotionMode::Walk: return planner::LocomotionMode::Walk;
  }
  return planner::LocomotionMode::Stand;
}
const char* modeName(planner::LocomotionMode m) {
  switch (m) {
    case planner::LocomotionMode::Stand: return "stand";
    case planner::LocomotionMode::StepInPlace: return "step_in_place";
    case planner::LocomotionMode::Walk: return "walk";
  }
  return "?";
}
planner::LocomotionMode toPlannerMode(std::uint8_t m) {
  return m == msg::LOCOMOTION_WALK ? planner::LocomotionMode::Walk
         : m == msg::LOCOMOTION_STEP_IN_PLACE ? planner::LocomotionMode::StepInPlace
                                              : planner::LocomotionMode::Stand;
}
}  // namespace

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-planner", "Motion planner service: RobotState (+ OperatorCommand) -> Reference.");
  services::ServiceContext::declareOptions(cli);
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  services::ServiceContext ctx("mft-planner", cli);

  planner::PlannerConfig config;
  std::string config_text;  // the base of live changes (docs/live-tuning.md)
  try {
    config = planner::loadPlannerConfig(ctx.configFile("planner.yaml"));
    config_text = services::configTextInForce(ctx.configFile("planner.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  std::unique_ptr<planner::MotionPlanner> planner_ptr;
  try {
    planner_ptr = std::make_unique<planner::MotionPlanner>(config, ctx.robot());
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  planner::MotionPlanner& planner = *planner_ptr;
  planner::PlannerStateBuilder state_builder(ctx.robot());

  std::mutex mutex;
  std::size_t next_command = 0;
  std::uint64_t last_tick = 0, ticks = 0, rejected = 0, refused_inputs = 0;
  bool answered = false;
  services::HopTrace hops("mft-planner", {"state_in", "write", "written"});
  services::TickGate gate;  // refuses a stray far tick, follows a restarted simulator (tick_gate.hpp)
  msg::Reference out_msg;
  model::RobotStateEstimate state;
  services::LatencyStats update_us;
  const auto& commands = ctx.scenario().commands;
  // Operator commands judged valid on arrival, applied at the next tick (fixed capacity: no allocation).
  struct PendingCommand {
    std::uint64_t seq;
    planner::OperatorCommand cmd;
  };
  std::array<PendingCommand, 32> pending{};
  std::size_t pending_count = 0;
  std::uint64_t operator_received = 0, operator_rejected = 0, operator_applied = 0;
  services::VerdictPublisher verdicts(ctx.participant(), "mft-planner", msg::COMMAND_SOURCE_PLANNER);
  // Live tuning (mft-cmd --set planner.<key>=<value>): judged off the loop by planner.yaml's strict loader, applied
  // at the tick boundary below (after the operator commands of the tick, before its plan).
  using Tuning = services::LiveTuning<planner::PlannerTuning>;
  Tuning tuning(ctx.participant(), "mft-planner", msg::CONFIG_TARGET_PLANNER, msg::COMMAND_SOURCE_PLANNER,
                ctx.lockstep(), services::tuningStatusFile(cli.get("summary")), config_text,
                [](const std::string& text, const std::string& key, const std::string& value) {
                  auto o = planner::applyPlannerOverride(text, "planner.yaml (live change)", key, value);
                  return Tuning::Judged{planner::tuningOf(o.config), std::move(o.yaml_text), std::move(o.value),
                                        std::move(o.previous)};
                });

  auto apply = [&](const planner::OperatorCommand& cmd, const char* origin) {
    const auto result = planner.setCommand(cmd);
    if (!result.accepted) {
      ++rejected;
      std::fprintf(stderr, "mft-planner: %s command rejected: %s\n", origin, result.reason.c_str());
    } else {
      std::printf("mft-planner: %s command: mode %d, height %.3f m, speed %.3f m/s\n", origin,
                  static_cast<int>(cmd.mode), cmd.z_cmd, cmd.v_cmd);
      std::fflush(stdout);
    }
  };

  services::TopicWriter<msg::Reference, msg::ReferencePubSubType> writer(ctx.participant(), "Reference",
                                                                         ctx.chainWriterProfile());
  services::TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader(
      ctx.participant(), "RobotState", ctx.chainReaderProfile(), [&](const msg::RobotState& m) {
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        if (!services::validInput(m)) {  // keep the last good state; the real sample of this tick still comes
          if (refused_inputs++ == 0) std::printf("mft-planner: refused a non-finite or implausible RobotState (tick %llu)\n", static_cast<unsigned long long>(m.tick()));
          return;
        }
        const auto decision = gate.check(m.tick());
        if (decision == services::TickGate::Decision::Refused) return;
        if (decision == services::TickGate::Decision::NewClock) {
          std::printf("mft-planner: the simulator's clock restarted (tick %llu after %llu)\n",
                      static_cast<unsigned long long>(m.tick()), static_cast<unsigned long long>(last_tick));
          answered = false;
          next_command = 0;  // the scenario's commands replay on the new clock
          planner.reset();   // a new world: plan from the robot's current state, not the old timeline's
        }
        if (answered && m.tick() == last_tick) {
          writer.write(out_msg);
          return;
        }
        if (answered && m.tick() < last_tick) return;
        const auto t0 = Clock::now();
        services::fromMsg(m, &state);
        while (next_command < commands.size() && commands[next_command].at_s <= state.time_s + 1e-9) {
          const auto& c = commands[next_command++];
          apply({c.z_cmd_m, c.v_cmd_mps, toPlannerMode(c.mode)}, "scenario");
        }
        // Operator commands after the scenario's of the same tick: the operator has the last word.
        for (std::size_t i = 0; i < pending_count; ++i) {
          const auto& p = pending[i];
          planner.setCommand(p.cmd);  // judged valid on arrival against the same fixed limits
          ++operator_applied;
          verdicts.post(p.seq, msg::VERDICT_APPLIED, m.tick(), m.stamp_ns(),
                        "mode %s, height %.3f m, speed %.3f m/s in force from tick %llu (t = %.3f s)", modeName(p.cmd.mode),
                        p.cmd.z_cmd, p.cmd.v_cmd, static_cast<unsigned long long>(m.tick()), state.time_s);
        }
        pending_count = 0;
        tuning.applyDue(m.tick(), state.time_s, m.stamp_ns(),
                        [&](const planner::PlannerTuning& t) { planner.setTuning(t); });
        const auto& plan = planner.update(state_builder.build(state));
        services::toMsg(plan, &out_msg);
        out_msg.tick(m.tick());
        out_msg.stamp_ns(m.stamp_ns());
        update_us.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
        hops.mark(1, m.tick());
        writer.write(out_msg);
        hops.mark(2, m.tick());
        last_tick = m.tick();
        gate.answered(last_tick);
        answered = true;
        ++ticks;
      });
  services::TopicReader<msg::OperatorCommand, msg::OperatorCommandPubSubType> command_reader(
      ctx.participant(), "OperatorCommand", "event_reader", [&](const msg::OperatorCommand& m) {
        std::lock_guard<std::mutex> lock(mutex);
        ++operator_received;
        const planner::OperatorCommand cmd{m.z_cmd(), m.v_cmd(), toPlannerMode(m.mode())};
        const auto check = planner::checkCommand(cmd, planner.limits());
        const char* why = !check.accepted                   ? check.reason.c_str()
                          : m.mode() > msg::LOCOMOTION_WALK ? "unknown locomotion mode (0 stand, 1 step_in_place, 2 walk)"
                          : !services::validInput(m)        ? "not finite or implausible"
                          : pending_count == pending.size() ? "too many commands waiting for the next tick"
                                                            : nullptr;
        if (why) {
          ++rejected;
          ++operator_rejected;
          std::fprintf(stderr, "mft-planner: operator command seq %llu rejected: %s\n",
                       static_cast<unsigned long long>(m.seq()), why);
          verdicts.post(m.seq(), msg::VERDICT_REJECTED, last_tick, 0, "%s", why);
          return;
        }
        pending[pending_count++] = {m.seq(), cmd};
        verdicts.post(m.seq(), msg::VERDICT_SCHEDULED, last_tick, 0,
                      "mode %s, height %.3f m, speed %.3f m/s accepted: in force from the next tick", modeName(cmd.mode),
                      cmd.z_cmd, cmd.v_cmd);
      });

  services::announceReady("mft-planner");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "{\"service\": \"mft-planner\", \"ticks\": %llu, \"last_tick\": %llu, \"steps\": %llu, "
                "\"rejected_commands\": %llu, \"operator_commands\": {\"received\": %llu, \"rejected\": %llu, "
                "\"applied\": %llu, \"waiting\": %zu}, \"refused_inputs\": %llu, \"refused_ticks\": %llu, \"new_clocks\": %llu, "
                "\"deadline_misses\": %llu, \"update_time_us\": ",
                static_cast<unsigned long long>(ticks), static_cast<unsigned long long>(last_tick),
                static_cast<unsigned long long>(planner.output().step_index),
                static_cast<unsigned long long>(rejected), static_cast<unsigned long long>(operator_received),
                static_cast<unsigned long long>(operator_rejected), static_cast<unsigned long long>(operator_applied),
                pending_count, static_cast<unsigned long long>(refused_inputs),
                static_cast<unsigned long long>(gate.refused()), static_cast<unsigned long long>(gate.newClocks()),
                static_cast<unsigned long long>(state_reader.requestedDeadlineMisses()));
  ctx.writeSummary(std::string(buf) + update_us.json() + ", \"live_changes\": " + tuning.summaryJson() + "}");
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-planner", [&] { return toolMain(argc, argv); });
}
