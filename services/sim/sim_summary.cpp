#include "services/sim/sim_summary.hpp"

#include <algorithm>
#include <cstdio>

namespace mft::services {
namespace {

std::string episodesJson(const chain::ActuatorDriver& driver, double now_s) {
  std::string out = "[";
  const auto& episodes = driver.episodes();
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    char e[96];
    std::snprintf(e, sizeof e, "%s[%.4f, %.3f, %.1f]", i ? ", " : "", episodes[i][0], episodes[i][1],
                  episodes[i][2] < 0 ? (now_s - episodes[i][0]) * 1e3 : episodes[i][2]);
    out += e;
  }
  return out + "]";
}

// Each miss judged against the machine's stalls (services/runtime/stall_probe.hpp).
std::string stallsJson(const StallProbe& probe, const chain::ActuatorDriver& driver) {
  const std::int64_t timeout_ns = driver.watchdogTimeoutNs();
  std::uint64_t explained = 0;
  std::string per_miss = "[";
  for (const std::int64_t deadline : driver.missedDeadlinesNs()) {
    const std::int64_t stalled = probe.stalledWhileWaitingNs(deadline, timeout_ns);
    if (StallProbe::explainsMiss(stalled, timeout_ns)) ++explained;
    char e[32];
    std::snprintf(e, sizeof e, "%s%.3f", per_miss.size() > 1 ? ", " : "", static_cast<double>(stalled) * 1e-6);
    per_miss += e;
  }
  const std::uint64_t misses = driver.watchdog().deadlineMisses();
  char pj[400];
  std::snprintf(pj, sizeof pj,
                ", \"cpu_stalls\": {\"probe_cpus\": %d, \"fifo\": %s, \"count\": %llu, \"max_ms\": %.3f, \"total_ms\": %.3f}, "
                "\"deadline_misses_during_cpu_stalls\": %llu, \"deadline_misses_unexplained\": %llu, \"miss_cpu_stalled_ms\": ",
                probe.cpus(), probe.realtimePriority() ? "true" : "false", static_cast<unsigned long long>(probe.stalls()),
                probe.maxStallMs(), probe.totalStallMs(), static_cast<unsigned long long>(explained),
                static_cast<unsigned long long>(misses - explained));
  return std::string(pj) + per_miss + "]";
}

}  // namespace

std::string simSummaryJson(const SimRun& r) {
  std::lock_guard<std::mutex> lock(r.link.mutex());
  const auto& driver = r.link.driver();
  const auto& watchdog = driver.watchdog();
  const auto& monitor = r.node.monitor();
  const auto& sim = r.node.simulator();
  const auto& stats = sim.stats();
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
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
      "\"commands_received\": %llu, \"commands_rejected\": {\"nonfinite\": %llu, \"out_of_range\": %llu, \"bad_mode\": %llu}, ",
      r.ctx.scenario().name.c_str(), r.ctx.lockstep() ? "lockstep" : "realtime", monitor.fell() ? "true" : "false",
      monitor.fallTime(), monitor.fallReason().c_str(), u(sim.tick()), sim.time(), r.wall_s, r.start_wait_s,
      sim.time() / std::max(r.wall_s, 1e-9), u(watchdog.deadlineMisses()), u(watchdog.lostCommands()),
      u(driver.dampingTicks()), u(driver.startupTicks()), u(r.resends), u(watchdog.recoveries()),
      u(r.link.requestedDeadlineMisses()), monitor.heightError().rms(), monitor.heightError().max_abs,
      monitor.pitchError().rms(), monitor.pitchError().max_abs, monitor.averageSpeed(), monitor.distance(),
      sim.groundTruth().q[1], stats.impulses.size(), stats.max_closure_error_m, u(stats.touchdowns[0]),
      u(stats.touchdowns[1]), r.error.c_str(), u(driver.commandsReceived()),
      u(driver.refused(chain::InputVerdict::NonFinite)), u(driver.refused(chain::InputVerdict::OutOfRange)),
      u(driver.refused(chain::InputVerdict::BadEnum)));
  char rec[300];
  std::snprintf(rec, sizeof rec,
                "\"recorder_window\": %llu, \"recorder_waits\": %llu, \"recorder_wait_s\": %.3f, \"recorder_complete\": %s, ",
                u(r.recorder.window()), u(r.recorder.waits()), r.recorder.waitSeconds(),
                r.recorder_complete ? "true" : "false");
  return std::string(buf) + r.pushes.countsJson() + rec + "\"profiles\": " + chain::profilesJson(r.ctx.profileNames()) +
         ", \"topic_pushes_applied\": " + r.pushes.appliedJson() + ", \"damping_episodes\": " +
         episodesJson(driver, sim.time()) + ", \"recovery\": " + r.node.recoveryJson() +
         ", \"latency_us\": " + r.link.latencyUs().json() +
         ", \"watchdog_detection_after_deadline_ms\": " + r.detection_ms.json() + r.pacer.json() +
         (r.stall_probe ? stallsJson(*r.stall_probe, driver) : std::string()) + "}";
}

}  // namespace mft::services
