#include "services/sim/sim_loop.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "common/strict_yaml.hpp"
#include "services/runtime/convert.hpp"
#include "services/sim/sim_summary.hpp"

namespace mft::services {

void SimLoop::declareOptions(CommandLine& cli) {
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
             "                             the deadline; docs/results/loop-benchmark.md) [us]", "0");
  cli.option("max-push", "largest disturbance impulse accepted from the Disturbance topic [N s]", "200");
  cli.option("recorder-window", "lockstep: never run more than this many ticks ahead of mft-record's progress "
                                "(0 = no recorder flow control; the supervisor sets it when recording)", "0");
  cli.flag("quiet", "no progress lines");
}

SimSetup SimLoop::load(const ServiceContext& ctx, const CommandLine& cli) {
  SimSetup setup;
  try {
    setup.options = sim::loadSimOptions(ctx.configFile("sim.yaml"));
    setup.terrain = sim::loadTerrain(ctx.configFile("terrain/" + ctx.scenario().terrain + ".yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  return setup;
}

namespace {
std::unique_ptr<chain::SimNode> makeNode(const ServiceContext& ctx, const CommandLine& cli, const SimSetup& setup) {
  try {
    return std::make_unique<chain::SimNode>(ctx.robot(), setup.options, setup.terrain, ctx.scenario(), 1.0);
  } catch (const std::invalid_argument& e) {
    cli.fail(ctx.scenario().source_file + ": the initial pose cannot be built: " + e.what());
  }
}
}  // namespace

// With DDS SensorData goes first (the estimator answers it; GroundTruth goes out while the chain computes); on the
// chain channel GroundTruth first, so that it is in its slot when SensorData wakes the estimator.
SimLoop::SimLoop(ServiceContext& ctx, const CommandLine& cli, const SimSetup& setup)
    : ctx_(ctx),
      cli_(cli),
      control_period_s_(setup.options.control_period_s),
      node_(makeNode(ctx, cli, setup)),
      command_timeout_(cli.getDouble("command-timeout", 0.01, 3600)),
      resend_(cli.getInt("resend-ms", 1, 10000)),
      start_timeout_(cli.getDouble("start-timeout", 0.1, 3600)),
      watchdog_ns_(static_cast<std::int64_t>(cli.getDouble("watchdog-ms", 1, 10000) * 1e6)),
      link_(ctx, hops_, ctx.robot().actuator.outputPeakTorque(), watchdog_ns_),
      pushes_(ctx, link_, cli.getDouble("max-push", 0.0, 1e4), control_period_s_),
      gait_(makeGaitLink(ctx, ctx.scenario())),
      recorder_(ctx, static_cast<std::uint64_t>(cli.getInt("recorder-window", 0, 1000000)), link_.mutex(),
                link_.arrived()),
      sensor_writer_(ctx.writing("SensorData")),
      truth_writer_(ctx.writing("GroundTruth")),
      truth_first_(sensor_writer_.viaChainChannel()) {}

int SimLoop::serve() {
  if (!awaitChain()) return 3;
  run();
  return finish();
}

void SimLoop::publish() {
  toMsg(node_->truth(), &truth_msg_);
  toMsg(node_->sensors(), &sensor_msg_);
  link_.published(node_->tick());
  hops_.mark(0, node_->tick());
  if (truth_first_) truth_writer_.write(truth_msg_);
  sensor_writer_.write(sensor_msg_);
  if (!truth_first_) truth_writer_.write(truth_msg_);
  hops_.mark(1, node_->tick());
}

bool SimLoop::awaitChain() {
  // The estimator listens, the controller's writer is there.
  const auto start_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(start_timeout_);
  if (!waitUntil([&] { return sensor_writer_.matched() > 0 && truth_writer_.matched() > 0 && link_.matchedWriters() > 0; },
                 std::chrono::duration_cast<std::chrono::milliseconds>(start_deadline - Clock::now()))) {
    std::fprintf(stderr, "mft-sim: the controller chain did not connect within %.0f s (SensorData readers %d, "
                 "JointCommand writers %d)\n", start_timeout_.count(), sensor_writer_.matched(), link_.matchedWriters());
    return false;
  }
  const auto* channel = ctx_.participant().chainChannel();
  if (channel && ctx_.lockstep()) channel->unlinkName();  // attached; in realtime a restarted service reopens it
  // Realtime starts once the chain answered tick 0: a lost discovery message can keep one hop unmatched for a
  // heartbeat period (seconds), and the robot would collapse in start-up damping meanwhile.
  if (!ctx_.lockstep() && !link_.awaitFirst(start_deadline, resend_, [this] { publish(); }) && !shutdownRequested()) {
    std::fprintf(stderr, "mft-sim: timeout: no JointCommand for tick 0 within %.0f s (is mft-wbc running?)\n",
                 start_timeout_.count());
    return false;
  }
  if (!ctx_.lockstep()) std::printf("mft-sim: the chain answered tick 0: the clock starts\n");  // `up` waits for it
  std::fflush(stdout);
  return true;
}

void SimLoop::run() {
  stall_probe_ = makeStallProbe(ctx_.lockstep() ? 0 : cli_.getInt("stall-probe-us", 0, 100000));
  enterLoopThread();  // realtime on the chain channel: this thread takes SCHED_FIFO on the chain's core
  pacer_.emplace(control_period_s_, watchdog_ns_, std::chrono::microseconds(cli_.getInt("spin-us", 0, 900)));
  exchange_.emplace(ctx_.lockstep(), TickExchange::Timeouts{command_timeout_, start_timeout_, resend_}, link_,
                    recorder_, *pacer_, hops_);
  const std::function<void()> publish_tick = [this] { publish(); };
  while (!shutdownRequested() && (cli_.isSet("forever") || node_->tick() < node_->ticksTotal())) {
    const std::uint64_t k = node_->tick();
    model::ActuatorCommand command;
    if (!exchange_->commandFor(k, node_->time(), publish_tick, &command, &error_)) break;
    if (!step(k, command)) break;
    reportProgress();
  }
}

// Tick k's physics step with its pushes; false when the robot fell and the run ends there.
bool SimLoop::step(std::uint64_t k, const model::ActuatorCommand& command) {
  pushes_.scheduleInto(*node_);
  const bool fell_now = node_->step(command, gait_ && node_->pushes().phasePushesWaiting()
                                                 ? gait_->forTick(k, std::chrono::milliseconds(2000))
                                                 : chain::GaitPhase{});
  hops_.mark(4, k);
  pushes_.reportApplied(*node_, k);
  if (!fell_now) return true;
  std::printf("mft-sim: FELL at t = %.3f s: %s\n", node_->monitor().fallTime(), node_->monitor().fallReason().c_str());
  std::fflush(stdout);
  return cli_.isSet("continue-after-fall");
}

void SimLoop::reportProgress() {
  if (cli_.isSet("quiet") || node_->tick() - last_progress_tick_ < 1000) return;
  last_progress_tick_ = node_->tick();
  const double wall = std::chrono::duration<double>(Clock::now() - exchange_->wallStart()).count();
  std::printf("mft-sim: t = %.1f s, %.2fx real time, base z %.4f m\n", node_->time(),
              node_->time() / std::max(wall, 1e-9), node_->truth().q[1]);
  std::fflush(stdout);
}

int SimLoop::finish() {
  const double wall_s = std::chrono::duration<double>(Clock::now() - exchange_->wallStart()).count();
  // A recorded run ends once the recorder holds the last tick on every topic: the supervisor stops every service
  // when the simulator exits, and samples still in a busy recorder's socket would be lost as their writers leave.
  const bool recorder_complete = node_->tick() == 0 || recorder_.awaitComplete(node_->tick() - 1);
  if (!error_.empty()) std::fprintf(stderr, "mft-sim: %s\n", error_.c_str());
  ctx_.writeSummary(simSummaryJson({ctx_, *node_, link_, recorder_, pushes_, *pacer_, stall_probe_.get(),
                                    exchange_->detectionMs(), error_, wall_s, exchange_->startWaitSeconds(),
                                    exchange_->resends(), recorder_complete}));
  return error_.empty() ? 0 : 3;
}

}  // namespace mft::services
