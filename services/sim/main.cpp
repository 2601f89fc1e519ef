// mft-sim: the simulator stage of the chain (chain/sim_node.hpp) as a service. It owns the clock
// (docs/architecture.md#clock-and-loop-modes):
//  lockstep: publish GroundTruth(k) and SensorData(k), wait for JointCommand(k), step; deterministic, as fast
//            as the chain answers; a missing answer is a named timeout error (exit status 3).
//  realtime: step on the wall clock at 1 kHz, hold the newest command; the actuator driver
//            (chain/actuator_driver.hpp) damps when commands stop, and resumes when they come back.
// It plays the scenario's pushes and the Disturbance topic's (topic_pushes.hpp), ends the run at the scenario's
// duration (or at a fall), and writes the run summary (sim_summary.hpp).
#include <cstdio>
#include <memory>

#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "services/runtime/convert.hpp"
#include "services/sim/check_scenario.hpp"
#include "services/sim/sim_summary.hpp"
#include "services/sim/gait_link.hpp"
#include "services/sim/tick_exchange.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

static int toolMain(int argc, char** argv) {
  if (services::isCheckScenario(argc, argv)) return services::checkScenario(argc, argv);
  services::CommandLine cli("mft-sim",
                            "ODE simulator service: owns the clock; JointCommand -> SensorData, GroundTruth.\n"
                            "Also: mft-sim --check-scenario FILE [--json] validates a scenario and exits.");
  services::ServiceContext::declareOptions(cli);
  cli.flag("forever", "ignore the scenario's duration: run until stopped");
  cli.flag("continue-after-fall", "keep running after a fall (default: the run ends at the fall)");
  cli.option("command-timeout", "lockstep: seconds to wait for each JointCommand", "5");
  cli.option("resend-ms", "lockstep: re-send a tick whose JointCommand is this late [ms]", "20");
  cli.option("start-timeout", "seconds to wait for the controller chain to connect and answer", "30");
  cli.option("watchdog-ms", "realtime: command timeout before the actuators damp [ms]", "3");
  cli.option("stall-probe-us", "realtime: period of the CPU stall probe (one SCHED_FIFO thread per CPU that tells\n"
             "                             the machine's stalls from the chain's misses; costs ~30 us of p50 latency\n"
             "                             on a 2-vCPU VM; 0 = off) [us]", "0");
  cli.option("spin-us", "realtime: wake this long before each 1 kHz deadline and poll the clock to it (0 = sleep to\n"
             "                             the deadline; docs/loop-benchmark.md) [us]", "0");
  cli.option("max-push", "largest disturbance impulse accepted from the Disturbance topic [N s]", "200");
  cli.option("recorder-window", "lockstep: never run more than this many ticks ahead of mft-record's progress "
                                "(0 = no recorder flow control; the supervisor sets it when recording)", "0");
  cli.flag("quiet", "no progress lines");
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  services::ServiceContext ctx("mft-sim", cli);
  const auto& scenario = ctx.scenario();
  sim::SimOptions options;
  sim::Terrain terrain;
  try {
    options = sim::loadSimOptions(ctx.configFile("sim.yaml"));
    terrain = sim::loadTerrain(ctx.configFile("terrain/" + scenario.terrain + ".yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  std::unique_ptr<chain::SimNode> node;
  try {
    node = std::make_unique<chain::SimNode>(ctx.robot(), options, terrain, scenario, 1.0);
  } catch (const std::invalid_argument& e) {
    cli.fail(scenario.source_file + ": the initial pose cannot be built: " + e.what());
  }
  const auto command_timeout = std::chrono::duration<double>(cli.getDouble("command-timeout", 0.01, 3600));
  const auto resend = std::chrono::milliseconds(cli.getInt("resend-ms", 1, 10000));
  const auto start_timeout = std::chrono::duration<double>(cli.getDouble("start-timeout", 0.1, 3600));
  const auto watchdog_ns = static_cast<std::int64_t>(cli.getDouble("watchdog-ms", 1, 10000) * 1e6);
  // publish: the tick's samples are written; command_in: its JointCommand reaches the listener; wake: the loop
  // holds it; stepped: the physics step is done.
  services::HopTrace hops("mft-sim", {"publish", "published", "command_in", "wake", "stepped"});
  services::CommandLink link(ctx, hops, ctx.robot().actuator.outputPeakTorque(), watchdog_ns);
  services::TopicPushes pushes(ctx, link, cli.getDouble("max-push", 0.0, 1e4), options.control_period_s);
  const auto gait = services::makeGaitLink(ctx, scenario);  // only for pushes at a gait phase
  services::RecorderFlow recorder(ctx, static_cast<std::uint64_t>(cli.getInt("recorder-window", 0, 1000000)),
                                  link.mutex(), link.arrived());
  services::TopicWriter<msg::SensorData, msg::SensorDataPubSubType> sensor_writer(ctx.participant(), "SensorData", ctx.chainWriterProfile());
  services::TopicWriter<msg::GroundTruth, msg::GroundTruthPubSubType> truth_writer(ctx.participant(), "GroundTruth", ctx.chainWriterProfile());
  services::announceReady("mft-sim");
  msg::SensorData sensor_msg;
  msg::GroundTruth truth_msg;
  // With DDS SensorData goes first (the estimator answers it; GroundTruth goes out while the chain computes); on
  // the chain channel GroundTruth first, so that it is in its slot when SensorData wakes the estimator.
  const bool truth_first = sensor_writer.viaChainChannel();
  auto publish = [&] {
    services::toMsg(node->truth(), &truth_msg);
    services::toMsg(node->sensors(), &sensor_msg);
    link.published(node->tick());
    hops.mark(0, node->tick());
    if (truth_first) truth_writer.write(truth_msg);
    sensor_writer.write(sensor_msg);
    if (!truth_first) truth_writer.write(truth_msg);
    hops.mark(1, node->tick());
  };
  const auto start_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(start_timeout);  // the estimator listens, the controller's writer is there
  if (!services::waitUntil([&] { return sensor_writer.matched() > 0 && truth_writer.matched() > 0 && link.matchedWriters() > 0; },
                           std::chrono::duration_cast<std::chrono::milliseconds>(start_deadline - Clock::now()))) {
    std::fprintf(stderr, "mft-sim: the controller chain did not connect within %.0f s (SensorData readers %d, "
                 "JointCommand writers %d)\n", start_timeout.count(), sensor_writer.matched(), link.matchedWriters());
    return 3;
  }
  const auto* channel = ctx.participant().chainChannel();
  if (channel && ctx.lockstep()) channel->unlinkName();  // attached; in realtime a restarted service reopens it
  // Realtime starts once the chain answered tick 0: a lost discovery message can keep one hop unmatched for a
  // heartbeat period (seconds), and the robot would collapse in start-up damping meanwhile.
  if (!ctx.lockstep() && !link.awaitFirst(start_deadline, resend, publish) && !services::shutdownRequested()) {
    std::fprintf(stderr, "mft-sim: timeout: no JointCommand for tick 0 within %.0f s (is mft-wbc running?)\n", start_timeout.count());
    return 3;
  }
  if (!ctx.lockstep()) std::printf("mft-sim: the chain answered tick 0: the clock starts\n");  // `up` waits for it
  std::fflush(stdout);
  const auto stall_probe = services::makeStallProbe(ctx.lockstep() ? 0 : cli.getInt("stall-probe-us", 0, 100000));
  services::RealtimePacer pacer(options.control_period_s, watchdog_ns,
                                std::chrono::microseconds(cli.getInt("spin-us", 0, 900)));
  services::TickExchange exchange(ctx.lockstep(), {command_timeout, start_timeout, resend}, link, recorder, pacer, hops);
  std::uint64_t last_progress_tick = 0;
  std::string error;
  while (!services::shutdownRequested() && (cli.isSet("forever") || node->tick() < node->ticksTotal())) {
    const std::uint64_t k = node->tick();
    model::ActuatorCommand command;
    if (!exchange.commandFor(k, node->time(), publish, &command, &error)) break;
    pushes.scheduleInto(*node);
    const bool fell_now = node->step(command, gait && node->pushes().phasePushesWaiting()
                                                  ? gait->forTick(k, std::chrono::milliseconds(2000))
                                                  : chain::GaitPhase{});
    hops.mark(4, k);
    pushes.reportApplied(*node, k);
    if (fell_now) {
      std::printf("mft-sim: FELL at t = %.3f s: %s\n", node->monitor().fallTime(), node->monitor().fallReason().c_str());
      std::fflush(stdout);
      if (!cli.isSet("continue-after-fall")) break;
    }
    if (!cli.isSet("quiet") && node->tick() - last_progress_tick >= 1000) {
      last_progress_tick = node->tick();
      const double wall = std::chrono::duration<double>(Clock::now() - exchange.wallStart()).count();
      std::printf("mft-sim: t = %.1f s, %.2fx real time, base z %.4f m\n", node->time(),
                  node->time() / std::max(wall, 1e-9), node->truth().q[1]);
      std::fflush(stdout);
    }
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - exchange.wallStart()).count();
  // A recorded run ends once the recorder holds the last tick on every topic: the supervisor stops every service
  // when the simulator exits, and samples still in a busy recorder's socket would be lost as their writers leave.
  const bool recorder_complete = node->tick() == 0 || recorder.awaitComplete(node->tick() - 1);
  if (!error.empty()) std::fprintf(stderr, "mft-sim: %s\n", error.c_str());
  ctx.writeSummary(services::simSummaryJson({ctx, *node, link, recorder, pushes, pacer, stall_probe.get(),
                                             exchange.detectionMs(), error, wall_s, exchange.startWaitSeconds(),
                                             exchange.resends(), recorder_complete}));
  return error.empty() ? 0 : 3;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-sim", [&] { return toolMain(argc, argv); });
}
