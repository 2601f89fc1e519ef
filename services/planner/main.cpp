// mft-planner: RobotState(k) -> the paper's motion planner -> Reference(k). Operator commands come from the
// scenario (at simulated times) and from the OperatorCommand topic (mft-cmd); a rejected command is reported
// and the last valid one stays in force.
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "MftMsgsPubSubTypes.h"
#include "model/config/strict_yaml.hpp"
#include "planner/motion_planner.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/latency_stats.hpp"
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
  try {
    config = planner::loadPlannerConfig(ctx.configFile("planner.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  std::unique_ptr<planner::MotionPlanner> planner_ptr;
  try {
    planner_ptr = std::make_unique<planner::MotionPlanner>(config, ctx.robot());
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  planner::MotionPlanner& planner = *planner_ptr;
  planner::PlannerStateBuilder state_builder(ctx.robot());

  std::mutex mutex;
  std::size_t next_command = 0;
  std::uint64_t last_tick = 0, ticks = 0, rejected = 0, refused_inputs = 0;
  bool answered = false;
  services::TickGate gate;  // refuses a stray far tick, follows a restarted simulator (tick_gate.hpp)
  msg::Reference out_msg;
  model::RobotStateEstimate state;
  services::LatencyStats update_us;
  const auto& commands = ctx.scenario().commands;

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
        const auto& plan = planner.update(state_builder.build(state));
        services::toMsg(plan, &out_msg);
        out_msg.tick(m.tick());
        out_msg.stamp_ns(m.stamp_ns());
        update_us.add(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
        writer.write(out_msg);
        last_tick = m.tick();
        gate.answered(last_tick);
        answered = true;
        ++ticks;
      });
  services::TopicReader<msg::OperatorCommand, msg::OperatorCommandPubSubType> command_reader(
      ctx.participant(), "OperatorCommand", "event_reader", [&](const msg::OperatorCommand& m) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!services::validInput(m)) {
          ++rejected;
          std::fprintf(stderr, "mft-planner: operator command rejected: not finite or implausible\n");
          return;
        }
        apply({m.z_cmd(), m.v_cmd(), toPlannerMode(m.mode())}, "operator");
      });

  services::announceReady("mft-planner");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "{\"service\": \"mft-planner\", \"ticks\": %llu, \"last_tick\": %llu, \"steps\": %llu, "
                "\"rejected_commands\": %llu, \"refused_inputs\": %llu, \"refused_ticks\": %llu, \"new_clocks\": %llu, "
                "\"deadline_misses\": %llu, \"update_time_us\": ",
                static_cast<unsigned long long>(ticks), static_cast<unsigned long long>(last_tick),
                static_cast<unsigned long long>(planner.output().step_index),
                static_cast<unsigned long long>(rejected), static_cast<unsigned long long>(refused_inputs),
                static_cast<unsigned long long>(gate.refused()), static_cast<unsigned long long>(gate.newClocks()),
                static_cast<unsigned long long>(state_reader.requestedDeadlineMisses()));
  ctx.writeSummary(std::string(buf) + update_us.json() + "}");
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-planner", [&] { return toolMain(argc, argv); });
}
