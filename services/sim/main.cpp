// mft-sim: the ODE simulator as a service. It owns the clock (docs/architecture.md#clock-and-loop-modes):
//  lockstep: publish GroundTruth(k) and SensorData(k), wait for JointCommand(k), step; deterministic, as fast
//            as the chain answers; a missing answer is a named timeout error (exit status 3).
//  realtime: step on the wall clock at 1 kHz (absolute deadlines), apply the latest command (zero-order hold);
//            the command watchdog puts the actuators into damping when commands stop, and back when they resume.
// It plays the scenario's pushes (and Disturbance messages from mft-cmd, each answered on CommandVerdict:
// rejected with the reason or scheduled on arrival, applied with the time and tick of the physics step that
// carried it; docs/operator-commands.md), ends the run at the scenario's duration (or at a fall), and writes
// the run summary.
#include <algorithm>
#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "model/config/profiles.hpp"
#include "model/config/strict_yaml.hpp"
#include "services/runtime/command_verdict.hpp"
#include "services/runtime/command_watchdog.hpp"
#include "services/runtime/stall_probe.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/input_guard.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/push_recovery.hpp"
#include "services/runtime/run_monitor.hpp"
#include "services/runtime/scenario_limits.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"
#include "sim/simulator.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;
using Clock = std::chrono::steady_clock;

namespace {

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// The scenario's initial pose: its base height and stance width, right foot ahead (0: both under the hip).
sim::StandingPose initialPose(const services::Scenario& scenario) {
  sim::StandingPose pose;
  pose.base_height_m = scenario.initial_base_height_m;
  pose.foot_offset_x_m = {0.5 * scenario.initial_stance_width_m, -0.5 * scenario.initial_stance_width_m};
  return pose;
}

// `mft-sim --check-scenario FILE [--json]`: validates a scenario and everything it names, starts nothing.
int checkScenario(int argc, char** argv) {
  services::CommandLine cli("mft-sim --check-scenario", "Validate a scenario file (and its terrain) and exit.");
  cli.option("check-scenario", "the scenario file", "", true);
  cli.option("config-dir", "configuration folder", config::configDirFor(MFT_CONFIG_DIR));
  cli.option("profile", "configuration profile, after the scenario's (repeatable): checked against every "
             "configuration file");
  cli.flag("json", "print the scenario as JSON (its profiles: the scenario's, then --profile)");
  cli.parse(argc, argv);
  try {
    auto scenario = services::loadScenario(cli.get("check-scenario"));
    scenario.profiles = services::activateRunProfiles(cli.get("config-dir"), scenario, cli.getAll("profile"));
    config::activeProfiles().check(cli.get("config-dir"));
    const auto robot = model::loadRobotDescription(cli.get("config-dir") + "/robot.yaml");
    const auto terrain = sim::loadTerrain(cli.get("config-dir") + "/terrain/" + scenario.terrain + ".yaml");
    const auto options = sim::loadSimOptions(cli.get("config-dir") + "/sim.yaml");
    services::checkScenarioLimits(scenario, robot, cli.get("config-dir") + "/planner.yaml");
    // And the initial pose exactly as mft-sim will build it, on this terrain.
    try {
      sim::Simulator simulator(robot, options, terrain);
      simulator.standingConfiguration(initialPose(scenario));
    } catch (const std::invalid_argument& e) {
      throw config::ConfigError(scenario.source_file + ": initial_base_height_m: the initial pose cannot be built on terrain '" +
                                scenario.terrain + "': " + e.what());
    }
    if (cli.isSet("json")) std::printf("%s\n", scenario.toJson().c_str());
    else std::printf("%s: scenario '%s' is valid (%.3f s, controller %s)\n", scenario.source_file.c_str(),
                     scenario.name.c_str(), scenario.duration_s, scenario.controller.c_str());
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}

// The height command in force at time t (for the height-error statistics).
double commandedHeight(const services::Scenario& s, double t) {
  double z = s.commands.front().z_cmd_m;
  for (const auto& c : s.commands)
    if (c.at_s <= t) z = c.z_cmd_m;
  return z;
}

}  // namespace

static int toolMain(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--check-scenario" || std::string(argv[i]).rfind("--check-scenario=", 0) == 0)
      return checkScenario(argc, argv);

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
  sim::Simulator simulator(ctx.robot(), options, terrain);
  try {
    simulator.reset(initialPose(scenario));
  } catch (const std::invalid_argument& e) {
    cli.fail(scenario.source_file + ": the initial pose cannot be built: " + e.what());
  }
  // Pushes at a time go to the simulator now; a push at a lift-off is armed only from its time on (the
  // simulator triggers at the next lift-off after it is scheduled).
  std::vector<std::pair<double, sim::ImpulseSpec>> armed_pushes;
  for (const auto& p : scenario.pushes) {
    sim::ImpulseSpec spec;
    spec.impulse_Ns = {p.impulse_Ns, 0.0};
    spec.time_s = p.at_s;
    spec.trigger = p.at_liftoff_leg < 0 ? sim::ImpulseTrigger::AtTime : sim::ImpulseTrigger::AtLiftOff;
    spec.leg = std::max(0, p.at_liftoff_leg);
    if (spec.trigger == sim::ImpulseTrigger::AtTime) simulator.scheduleImpulse(spec);
    else armed_pushes.emplace_back(p.at_s, spec);
  }

  const double command_timeout_s = cli.getDouble("command-timeout", 0.01, 3600);
  const auto resend_ms = static_cast<int>(cli.getInt("resend-ms", 1, 10000));
  const double start_timeout_s = cli.getDouble("start-timeout", 0.1, 3600);
  const auto watchdog_timeout_ns = static_cast<std::int64_t>(cli.getDouble("watchdog-ms", 1, 10000) * 1e6);
  services::CommandWatchdog watchdog(watchdog_timeout_ns);
  services::LatencyStats detection_ms(10000);
  bool damping_now = false;
  double damping_onset_s = 0.0;  // sim time of the current damping episode's onset
  std::vector<std::array<double, 3>> episodes;  // damping episodes: [onset sim time s, ms after deadline, duration ms]
  std::vector<double> onset_sim_late_ms;         // per miss: the simulator's own worst lateness in the 8 periods before
  episodes.reserve(64);                          // both capped at 64: nothing allocates in the loop
  onset_sim_late_ms.reserve(64);
  std::array<double, 8> recent_late_us{};        // its lateness over the last 8 periods
  std::size_t recent_index = 0;
  std::uint64_t sim_stalls = 0;                  // simulator wake-ups later than the watchdog timeout
  // Per counted miss, the deadline it missed: judged after the run against the CPU stall probe (a stall
  // still going on at detection is recorded only when it ends).
  std::vector<std::int64_t> missed_deadlines_ns;
  missed_deadlines_ns.reserve(256);
  const bool quiet = cli.isSet("quiet");
  const double max_push_Ns = cli.getDouble("max-push", 0.0, 1e4);
  const double peak_torque = ctx.robot().actuator.outputPeakTorque();
  // What the network delivered and what the actuator driver refused (docs/faults.md).
  std::uint64_t commands_received = 0, disturbances_rejected = 0;
  std::array<std::uint64_t, 4> commands_rejected{};  // by InputVerdict

  // Commands arrive on a DDS thread; the loop below owns the simulator.
  std::mutex mutex;
  std::condition_variable arrived;
  model::ActuatorCommand latest;
  bool have_command = false;
  std::vector<sim::ImpulseSpec> pending_pushes;
  pending_pushes.reserve(64);
  // Pushes from the Disturbance topic in flight: ImpulseSpec::id (1, 2, ...) -> the request's seq. Fixed
  // capacity: the loop never allocates; a request beyond it is rejected.
  struct TopicPush {
    std::uint64_t id = 0, seq = 0;
  };
  std::array<TopicPush, 64> topic_pushes{};
  std::uint64_t next_push_id = 1, disturbances_received = 0, disturbances_applied = 0;
  std::vector<std::array<double, 3>> applied_topic_pushes;  // [impulse N s, time s, tick] for the summary
  applied_topic_pushes.reserve(64);
  services::VerdictPublisher verdicts(ctx.participant(), "mft-sim", msg::COMMAND_SOURCE_SIMULATOR);
  std::array<std::int64_t, 1024> publish_ns{};  // when SensorData(k) left, by k % 1024 (realtime latency)
  services::LatencyStats latency_us;
  std::uint64_t published_tick = 0;
  // Realtime watchdog input: the newest tick a command answered, and when the oldest unanswered tick left.
  std::uint64_t answered_tick = 0;
  bool any_answer = false;
  const auto waitingSinceNs = [&]() -> std::int64_t {  // under `mutex`
    if (!any_answer || answered_tick >= published_tick) return services::CommandWatchdog::kNothingWaiting;
    const std::uint64_t oldest = answered_tick + 1;
    const std::uint64_t n = publish_ns.size();
    // Older than the ring: its oldest entry is the earliest publication still known (conservative).
    return publish_ns[(published_tick - oldest >= n ? published_tick + 1 : oldest) % n];
  };
  // publish: the tick's samples are written; command_in: its JointCommand reaches the listener; wake: the loop
  // holds it; stepped: the physics step is done.
  services::HopTrace hops("mft-sim", {"publish", "published", "command_in", "wake", "stepped"});
  services::LatencyStats wakeup_late_us;  // realtime: how late the simulator's own loop woke up

  services::TopicWriter<msg::SensorData, msg::SensorDataPubSubType> sensor_writer(ctx.participant(), "SensorData",
                                                                                  ctx.chainWriterProfile());
  services::TopicWriter<msg::GroundTruth, msg::GroundTruthPubSubType> truth_writer(ctx.participant(), "GroundTruth",
                                                                                   ctx.chainWriterProfile());
  services::TopicReader<msg::JointCommand, msg::JointCommandPubSubType> command_reader(
      ctx.participant(), "JointCommand", ctx.chainReaderProfile(), [&](const msg::JointCommand& m) {
        hops.mark(2, m.tick());
        const std::int64_t t = nowNs();
        std::lock_guard<std::mutex> lock(mutex);
        ++commands_received;
        // A command that is not finite, beyond the peak torque or of an unknown mode never reaches the
        // actuators: it counts as a missing command (the watchdog damps when only such commands come).
        const auto verdict = services::checkJointCommand(m.tau(), m.mode(), peak_torque);
        if (verdict != services::InputVerdict::Ok) {
          if (commands_rejected[static_cast<int>(verdict)]++ == 0)
            std::printf("mft-sim: refused a JointCommand (tick %llu): %s\n", static_cast<unsigned long long>(m.tick()),
                        services::toString(verdict));
          return;
        }
        services::fromMsg(m, &latest);
        have_command = true;
        watchdog.onCommand(m.seq(), t);
        if (!any_answer || m.tick() > answered_tick) answered_tick = m.tick();
        any_answer = true;
        if (!ctx.lockstep() && m.tick() == published_tick)
          latency_us.add(static_cast<double>(t - publish_ns[m.tick() % publish_ns.size()]) * 1e-3);
        arrived.notify_all();
      });
  services::TopicReader<msg::Disturbance, msg::DisturbancePubSubType> push_reader(
      ctx.participant(), "Disturbance", "event_reader", [&](const msg::Disturbance& m) {
        const auto verdict = services::checkDisturbance(m.impulse(), m.trigger(), m.time_s(), m.leg(), max_push_Ns);
        std::lock_guard<std::mutex> lock(mutex);
        ++disturbances_received;
        const double now_s = static_cast<double>(published_tick) * options.control_period_s;
        TopicPush* slot = nullptr;
        for (auto& p : topic_pushes)
          if (p.id == 0) {
            slot = &p;
            break;
          }
        if (verdict != services::InputVerdict::Ok || !slot) {
          if (disturbances_rejected++ < 3)
            std::printf("mft-sim: refused a Disturbance (seq %llu): %s\n", static_cast<unsigned long long>(m.seq()),
                        slot ? services::toString(verdict) : "too many pushes waiting");
          const auto seq = m.seq();
          if (!slot)
            verdicts.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "%zu pushes are already waiting to be applied",
                          topic_pushes.size());
          else if (verdict == services::InputVerdict::NonFinite)
            verdicts.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "impulse or time is not a finite number");
          else if (verdict == services::InputVerdict::BadEnum)
            verdicts.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "unknown trigger %d or leg %d (0 right, 1 left)",
                          m.trigger(), m.leg());
          else if (m.time_s() < 0.0)
            verdicts.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "negative time %.3f s", m.time_s());
          else
            verdicts.post(seq, msg::VERDICT_REJECTED, published_tick, 0,
                          "impulse %.3f N s beyond the largest accepted push %.3f N s (mft-sim --max-push)",
                          m.impulse(), max_push_Ns);
          return;
        }
        sim::ImpulseSpec spec;
        spec.impulse_Ns = {m.impulse(), 0.0};
        spec.time_s = m.time_s();
        spec.trigger = m.trigger() == msg::TRIGGER_AT_NEXT_LIFTOFF ? sim::ImpulseTrigger::AtLiftOff
                                                                    : sim::ImpulseTrigger::AtTime;
        spec.leg = std::max<int>(0, m.leg());
        spec.id = next_push_id++;
        *slot = {spec.id, m.seq()};
        pending_pushes.push_back(spec);
        if (spec.trigger == sim::ImpulseTrigger::AtLiftOff)
          verdicts.post(m.seq(), msg::VERDICT_SCHEDULED, published_tick, 0,
                        "push of %.3f N s will be applied at the next %s-foot lift-off", m.impulse(),
                        spec.leg == 0 ? "right" : "left");
        else
          verdicts.post(m.seq(), msg::VERDICT_SCHEDULED, published_tick, 0, "push of %.3f N s will be applied at t = %.3f s",
                        m.impulse(), std::max(spec.time_s, now_s));
      });
  // Lockstep recording: a starved recorder must slow the simulator down, not lose samples in its socket buffer.
  const auto recorder_window = static_cast<std::uint64_t>(cli.getInt("recorder-window", 0, 1000000));
  std::uint64_t recorder_tick = 0, recorder_all_tick = 0, recorder_waits = 0;
  bool recorder_heard = false;  // the recorder receives every 1 kHz topic
  double recorder_wait_s = 0.0;
  std::unique_ptr<services::TopicReader<msg::RecorderProgress, msg::RecorderProgressPubSubType>> progress_reader;
  if (recorder_window > 0 && ctx.lockstep())
    progress_reader = std::make_unique<services::TopicReader<msg::RecorderProgress, msg::RecorderProgressPubSubType>>(
        ctx.participant(), "RecorderProgress", "lockstep_reader", [&](const msg::RecorderProgress& m) {
          std::lock_guard<std::mutex> lock(mutex);
          recorder_heard = true;
          recorder_tick = std::max(recorder_tick, m.tick());
          recorder_all_tick = std::max(recorder_all_tick, m.all_topics_tick());
          arrived.notify_all();
        });
  services::announceReady("mft-sim");

  msg::SensorData sensor_msg;
  msg::GroundTruth truth_msg;
  auto publish = [&] {
    services::toMsg(simulator.groundTruth(), &truth_msg);
    services::toMsg(simulator.sensors(), &sensor_msg);
    {
      std::lock_guard<std::mutex> lock(mutex);
      published_tick = simulator.tick();
      publish_ns[published_tick % publish_ns.size()] = nowNs();
    }
    hops.mark(0, simulator.tick());
    // SensorData first: it is what the estimator answers; GroundTruth (needed by the estimator only at its
    // first tick and in ground-truth mode, where it waits for both) then goes out while the chain computes.
    sensor_writer.write(sensor_msg);
    truth_writer.write(truth_msg);
    hops.mark(1, simulator.tick());
  };

  // Readiness of the chain: the estimator listens and the controller's command writer is there.
  const auto start_deadline = Clock::now() + std::chrono::duration<double>(start_timeout_s);
  if (!services::waitUntil([&] { return sensor_writer.matched() > 0 && truth_writer.matched() > 0 && command_reader.matched() > 0; },
                           std::chrono::duration_cast<std::chrono::milliseconds>(start_deadline - Clock::now()))) {
    std::fprintf(stderr, "mft-sim: the controller chain did not connect within %.0f s (SensorData readers %d, "
                         "JointCommand writers %d)\n", start_timeout_s, sensor_writer.matched(), command_reader.matched());
    return 3;
  }

  services::FallCriteria criteria;
  criteria.base_height_below_m = scenario.fall_base_height_m;
  criteria.pitch_beyond_rad = scenario.fall_pitch_rad;
  services::RunMonitor monitor(criteria, 1.0);
  services::RecoveryWindow recovery(scenario.recovery.window_s, options.control_period_s);  // push-recovery verdict
  std::size_t impulses_seen = 0;
  const bool forever = cli.isSet("forever");
  const auto ticks_total = static_cast<std::uint64_t>(std::llround(scenario.duration_s / options.control_period_s));
  std::uint64_t damping_ticks = 0, startup_ticks = 0, last_progress_tick = 0, resends = 0;
  int exit_code = 0;
  std::string error;
  if (!ctx.lockstep()) {
    // Realtime: the clock starts once the chain has answered tick 0. Matching the endpoints is not enough:
    // a discovery message lost on a busy machine can keep one hop of the chain unmatched for up to a
    // heartbeat period (seconds), and the robot would collapse in start-up damping meanwhile.
    std::unique_lock<std::mutex> lock(mutex);
    while (!have_command && !services::shutdownRequested() && Clock::now() < start_deadline) {
      lock.unlock();
      publish();
      lock.lock();
      arrived.wait_for(lock, std::chrono::milliseconds(resend_ms));
    }
    if (!have_command && !services::shutdownRequested()) {
      std::fprintf(stderr, "mft-sim: timeout: no JointCommand for tick 0 within %.0f s (is mft-wbc running?)\n", start_timeout_s);
      return 3;
    }
    std::printf("mft-sim: the chain answered tick 0: the clock starts\n");  // the supervisor's `up` waits for it
    std::fflush(stdout);
  }
  std::unique_ptr<services::StallProbe> stall_probe;
  const auto stall_probe_us = cli.getInt("stall-probe-us", 0, 100000);
  if (!ctx.lockstep() && stall_probe_us > 0) {
    services::StallProbe::Options o;
    o.period = std::chrono::microseconds(stall_probe_us);
    o.threshold = std::chrono::microseconds(std::max<long>(stall_probe_us, 1000));
    stall_probe = std::make_unique<services::StallProbe>(o);
  }
  auto wall_start = Clock::now();
  auto next_wakeup = wall_start;
  double start_wait_s = 0;  // lockstep: until the chain (and the recorder) answered tick 0; not loop time
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.control_period_s));

  while (!services::shutdownRequested() && (forever || simulator.tick() < ticks_total)) {
    const std::uint64_t k = simulator.tick();
    if (progress_reader) {
      std::unique_lock<std::mutex> lock(mutex);
      if (k > recorder_tick + recorder_window) {
        ++recorder_waits;
        const auto t0 = Clock::now();
        const auto deadline = t0 + std::chrono::duration<double>(command_timeout_s);
        while (k > recorder_tick + recorder_window && !services::shutdownRequested() && Clock::now() < deadline)
          arrived.wait_for(lock, std::chrono::milliseconds(10));
        recorder_wait_s += std::chrono::duration<double>(Clock::now() - t0).count();
        if (k > recorder_tick + recorder_window && !services::shutdownRequested()) {
          char buf[200];
          std::snprintf(buf, sizeof buf, "timeout: mft-record confirmed only tick %llu of %llu within %.1f s (is it running?)",
                        static_cast<unsigned long long>(recorder_tick), static_cast<unsigned long long>(k), command_timeout_s);
          error = buf;
          exit_code = 3;
          break;
        }
      }
    }
    publish();
    model::ActuatorCommand command;
    if (ctx.lockstep()) {
      // Wait for JointCommand(k); re-send tick k when it is late. The chain is best effort (a lost sample
      // costs one re-send instead of reliable QoS on every hop), samples written just after matching can be
      // lost (docs/dds.md#samples-before-matching), and every service answers a repeated tick with its cached answer.
      std::unique_lock<std::mutex> lock(mutex);
      const auto deadline = Clock::now() + std::chrono::duration<double>(k == 0 ? start_timeout_s : command_timeout_s);
      // Tick 0 of a recorded run is held (and re-sent) until the recorder receives every topic.
      const auto answered = [&] { return have_command && latest.tick == k && (k > 0 || !progress_reader || recorder_heard); };
      while (!answered() && !services::shutdownRequested()) {
        if (Clock::now() > deadline) break;
        if (arrived.wait_for(lock, std::chrono::milliseconds(k == 0 ? 100 : resend_ms)) == std::cv_status::timeout) {
          lock.unlock();
          publish();
          if (k > 0) ++resends;
          lock.lock();
        }
      }
      if (services::shutdownRequested()) break;
      if (!answered()) {
        char buf[200];
        if (have_command && latest.tick == k)
          std::snprintf(buf, sizeof buf, "timeout: mft-record did not receive every topic within %.1f s (is it running?)",
                        start_timeout_s);
        else
          std::snprintf(buf, sizeof buf, "timeout: no JointCommand for tick %llu within %.1f s (is mft-wbc running?)",
                        static_cast<unsigned long long>(k), k == 0 ? start_timeout_s : command_timeout_s);
        error = buf;
        exit_code = 3;
        break;
      }
      command = latest;
      hops.mark(3, k);
      if (k == 0) {
        // The loop's wall time starts here, as in realtime: tick 0 waits for discovery (and for the recorder
        // to hear every topic), re-sent every 100 ms, which is start-up, not the speed of the loop.
        const auto answered_at = Clock::now();
        start_wait_s = std::chrono::duration<double>(answered_at - wall_start).count();
        wall_start = answered_at;
        std::printf("mft-sim: the chain answered tick 0: the clock starts\n");  // the supervisor's `up` waits for it
        std::fflush(stdout);
      }
    } else {
      next_wakeup += period;
      std::this_thread::sleep_until(next_wakeup);
      const auto woke = Clock::now();
      const double woke_late_us = std::chrono::duration<double, std::micro>(woke - next_wakeup).count();
      wakeup_late_us.add(woke_late_us);
      recent_late_us[recent_index++ % recent_late_us.size()] = woke_late_us;
      // The simulator itself slept through a whole watchdog timeout: the machine stalled (a VM's vCPUs
      // descheduled), and the controller with it. Misses then are the machine's, not the chain's.
      if (woke_late_us * 1e3 > static_cast<double>(watchdog_timeout_ns)) ++sim_stalls;
      std::lock_guard<std::mutex> lock(mutex);
      command = latest;  // zero-order hold of the newest command
      const bool was_damping = damping_now;
      const std::uint64_t misses_before = watchdog.deadlineMisses();
      damping_now = have_command && watchdog.damping(nowNs(), waitingSinceNs());
      // One entry per counted miss (a recovery and a new miss between two periods count as two).
      if (watchdog.deadlineMisses() > misses_before && onset_sim_late_ms.size() < 64)
        onset_sim_late_ms.push_back(*std::max_element(recent_late_us.begin(), recent_late_us.end()) * 1e-3);
      if (watchdog.deadlineMisses() > misses_before && missed_deadlines_ns.size() < missed_deadlines_ns.capacity())
        missed_deadlines_ns.push_back(watchdog.missedDeadlineNs());
      if (damping_now && !was_damping) {
        // How long after the deadline (the waiting tick's publication + timeout) the actuators went into damping.
        const double late_ms = static_cast<double>(watchdog.dampingSinceNs() - watchdog.missedDeadlineNs()) * 1e-6;
        detection_ms.add(late_ms);
        if (episodes.size() < 64) episodes.push_back({simulator.time(), late_ms, -1.0});
        std::printf("mft-sim: a tick waited %.1f ms for its command: actuators damping (t = %.3f s)\n",
                    static_cast<double>(watchdog_timeout_ns) * 1e-6 + late_ms, simulator.time());
        std::fflush(stdout);
      }
      if (damping_now && !was_damping) damping_onset_s = simulator.time();
      if (was_damping && !damping_now) {
        if (!episodes.empty() && episodes.back()[2] < 0) episodes.back()[2] = (simulator.time() - episodes.back()[0]) * 1e3;
        // The counterpart of the onset line: tests wait for it instead of sleeping until commands flow again.
        std::printf("mft-sim: commands resumed after %.1f ms of damping (t = %.3f s)\n",
                    (simulator.time() - damping_onset_s) * 1e3, simulator.time());
        std::fflush(stdout);
      }
      if (!have_command) {
        command.mode = model::CommandMode::Damping;  // start-up: the first command is still on its way
        ++startup_ticks;
      } else if (damping_now) {
        command.mode = model::CommandMode::Damping;
        ++damping_ticks;
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (const auto& p : pending_pushes) simulator.scheduleImpulse(p);
      pending_pushes.clear();
    }
    for (auto it = armed_pushes.begin(); it != armed_pushes.end();) {
      if (it->first <= simulator.time() + 1e-9) {
        simulator.scheduleImpulse(it->second);
        it = armed_pushes.erase(it);
      } else {
        ++it;
      }
    }
    simulator.setCommand(command);
    simulator.step();
    hops.mark(4, k);
    const bool fell_now = monitor.update(simulator.groundTruth(), commandedHeight(scenario, simulator.time()),
                                         simulator.stats().body_contact_steps);
    {
      const auto& st = simulator.stats();
      for (; impulses_seen < st.impulses.size(); ++impulses_seen) {
        const auto& applied = st.impulses[impulses_seen];
        recovery.onImpulse(applied.time_s, applied.impulse_Ns.x());
        if (applied.id == 0) continue;  // a scenario push
        std::lock_guard<std::mutex> lock(mutex);
        for (auto& p : topic_pushes)
          if (p.id == applied.id) {
            ++disturbances_applied;
            if (applied_topic_pushes.size() < applied_topic_pushes.capacity())
              applied_topic_pushes.push_back({applied.impulse_Ns.x(), applied.time_s, static_cast<double>(k)});
            verdicts.post(p.seq, msg::VERDICT_APPLIED, k, static_cast<std::uint64_t>(std::llround(applied.time_s * 1e9)),
                          "push of %.3f N s applied at t = %.4f s (tick %llu)", applied.impulse_Ns.x(), applied.time_s,
                          static_cast<unsigned long long>(k));
            p = TopicPush{};
          }
      }
      recovery.update(simulator.groundTruth(), st.touchdowns[0] + st.touchdowns[1]);
    }
    if (fell_now) {
      std::printf("mft-sim: FELL at t = %.3f s: %s\n", monitor.fallTime(), monitor.fallReason().c_str());
      std::fflush(stdout);
      if (!cli.isSet("continue-after-fall")) break;
    }
    if (!quiet && simulator.tick() - last_progress_tick >= 1000) {
      last_progress_tick = simulator.tick();
      const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
      std::printf("mft-sim: t = %.1f s, %.2fx real time, base z %.4f m\n", simulator.time(),
                  simulator.time() / std::max(wall, 1e-9), simulator.groundTruth().q[1]);
      std::fflush(stdout);
    }
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  // A recorded lockstep run ends once the recorder holds the last tick on every topic (at most 2 s): the
  // supervisor stops every service when the simulator exits, and samples still waiting in a busy recorder's
  // socket would be discarded as their writers leave.
  bool recorder_complete = true;
  if (progress_reader && simulator.tick() > 0) {
    const std::uint64_t last = simulator.tick() - 1;
    std::unique_lock<std::mutex> lock(mutex);
    const auto deadline = Clock::now() + std::chrono::seconds(2);
    while (recorder_all_tick < last && !services::shutdownRequested() && Clock::now() < deadline)
      arrived.wait_for(lock, std::chrono::milliseconds(10));
    recorder_complete = recorder_all_tick >= last;
  }
  if (!error.empty()) std::fprintf(stderr, "mft-sim: %s\n", error.c_str());

  const auto& stats = simulator.stats();
  char buf[3000];
  std::snprintf(
      buf, sizeof buf,
      "{\"service\": \"mft-sim\", \"scenario\": \"%s\", \"mode\": \"%s\", \"fell\": %s, \"fall_time_s\": %.4f, "
      "\"fall_reason\": \"%s\", \"ticks\": %llu, \"sim_time_s\": %.4f, \"wall_time_s\": %.3f, \"start_wait_s\": %.3f, "
      "\"real_time_factor\": %.3f, \"deadline_misses\": %llu, \"lost_commands\": %llu, \"damping_ticks\": %llu, "
      "\"startup_ticks\": %llu, \"lockstep_resends\": %llu, \"watchdog_recoveries\": %llu, \"reader_deadline_misses\": %llu, "
      "\"base_height_error_m\": {\"rms\": %.6f, \"max\": %.6f}, \"pitch_error_rad\": {\"rms\": %.6f, \"max\": %.6f}, "
      "\"average_speed_mps\": %.5f, \"distance_m\": %.5f, \"final_base_height_m\": %.5f, \"impulses_applied\": %zu, "
      "\"max_closure_error_m\": %.3g, \"touchdowns\": [%llu, %llu], \"error\": \"%s\", "
      "\"commands_received\": %llu, \"commands_rejected\": {\"nonfinite\": %llu, \"out_of_range\": %llu, \"bad_mode\": %llu}, "
      "\"disturbances_received\": %llu, \"disturbances_applied\": %llu, "
      "\"disturbances_rejected\": %llu, \"recorder_window\": %llu, \"recorder_waits\": %llu, \"recorder_wait_s\": %.3f, \"recorder_complete\": %s, ",
      scenario.name.c_str(), ctx.lockstep() ? "lockstep" : "realtime", monitor.fell() ? "true" : "false",
      monitor.fallTime(), monitor.fallReason().c_str(), static_cast<unsigned long long>(simulator.tick()),
      simulator.time(), wall_s, start_wait_s, simulator.time() / std::max(wall_s, 1e-9),
      static_cast<unsigned long long>(watchdog.deadlineMisses()), static_cast<unsigned long long>(watchdog.lostCommands()),
      static_cast<unsigned long long>(damping_ticks), static_cast<unsigned long long>(startup_ticks),
      static_cast<unsigned long long>(resends), static_cast<unsigned long long>(watchdog.recoveries()),
      static_cast<unsigned long long>(command_reader.requestedDeadlineMisses()), monitor.heightError().rms(),
      monitor.heightError().max_abs, monitor.pitchError().rms(), monitor.pitchError().max_abs, monitor.averageSpeed(),
      monitor.distance(), simulator.groundTruth().q[1], stats.impulses.size(), stats.max_closure_error_m,
      static_cast<unsigned long long>(stats.touchdowns[0]), static_cast<unsigned long long>(stats.touchdowns[1]),
      error.c_str(), static_cast<unsigned long long>(commands_received),
      static_cast<unsigned long long>(commands_rejected[1]), static_cast<unsigned long long>(commands_rejected[2]),
      static_cast<unsigned long long>(commands_rejected[3]), static_cast<unsigned long long>(disturbances_received),
      static_cast<unsigned long long>(disturbances_applied), static_cast<unsigned long long>(disturbances_rejected),
      static_cast<unsigned long long>(progress_reader ? recorder_window : 0), static_cast<unsigned long long>(recorder_waits),
      recorder_wait_s, recorder_complete ? "true" : "false");
  std::string onset_json = "[";
  for (std::size_t i = 0; i < onset_sim_late_ms.size(); ++i) {
    char e[32];
    std::snprintf(e, sizeof e, "%s%.3f", i ? ", " : "", onset_sim_late_ms[i]);
    onset_json += e;
  }
  onset_json += "]";
  std::string pushes_json = "[";
  for (std::size_t i = 0; i < applied_topic_pushes.size(); ++i) {
    char e[96];
    std::snprintf(e, sizeof e, "%s[%.4f, %.4f, %.0f]", i ? ", " : "", applied_topic_pushes[i][0],
                  applied_topic_pushes[i][1], applied_topic_pushes[i][2]);
    pushes_json += e;
  }
  pushes_json += "]";
  std::string episode_json = "[";
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    char e[96];
    std::snprintf(e, sizeof e, "%s[%.4f, %.3f, %.1f]", i ? ", " : "", episodes[i][0], episodes[i][1],
                  episodes[i][2] < 0 ? (simulator.time() - episodes[i][0]) * 1e3 : episodes[i][2]);
    episode_json += e;
  }
  episode_json += "]";
  // Each miss judged against the machine's stalls (services/runtime/stall_probe.hpp).
  std::string probe_json;
  if (stall_probe) {
    std::uint64_t explained = 0;
    std::string per_miss = "[";
    for (const std::int64_t deadline : missed_deadlines_ns) {
      const std::int64_t stalled = stall_probe->stalledWhileWaitingNs(deadline, watchdog_timeout_ns);
      if (services::StallProbe::explainsMiss(stalled, watchdog_timeout_ns)) ++explained;
      char e[32];
      std::snprintf(e, sizeof e, "%s%.3f", per_miss.size() > 1 ? ", " : "", static_cast<double>(stalled) * 1e-6);
      per_miss += e;
    }
    per_miss += "]";
    const std::uint64_t misses = watchdog.deadlineMisses();
    char pj[400];
    std::snprintf(pj, sizeof pj,
                  ", \"cpu_stalls\": {\"probe_cpus\": %d, \"fifo\": %s, \"count\": %llu, \"max_ms\": %.3f, \"total_ms\": %.3f}, "
                  "\"deadline_misses_during_cpu_stalls\": %llu, \"deadline_misses_unexplained\": %llu, \"miss_cpu_stalled_ms\": ",
                  stall_probe->cpus(), stall_probe->realtimePriority() ? "true" : "false",
                  static_cast<unsigned long long>(stall_probe->stalls()), stall_probe->maxStallMs(), stall_probe->totalStallMs(),
                  static_cast<unsigned long long>(explained), static_cast<unsigned long long>(misses - explained));
    probe_json = std::string(pj) + per_miss;
  }
  ctx.writeSummary(std::string(buf) + "\"profiles\": " + services::profilesJson(ctx.profileNames()) +
                   ", \"topic_pushes_applied\": " + pushes_json + ", \"damping_episodes\": " + episode_json + ", \"recovery\": " +
                   recovery.json(scenario.recovery, monitor.fell(), monitor.fallTime(), monitor.fallReason()) +
                   ", \"latency_us\": " + latency_us.json() +
                   ", \"watchdog_detection_after_deadline_ms\": " + detection_ms.json() +
                   ", \"sim_wakeup_late_us\": " + wakeup_late_us.json() + ", \"sim_stalls\": " +
                   std::to_string(sim_stalls) + ", \"damping_onset_sim_late_ms\": " + onset_json + probe_json + "}");
  return exit_code;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-sim", [&] { return toolMain(argc, argv); });
}
