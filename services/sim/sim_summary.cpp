#include "services/sim/sim_summary.hpp"

#include <algorithm>
#include <vector>

#include "common/json_writer.hpp"

namespace mft::services {
namespace {

// [[start s, ramp s, length ms], ...]; an episode still running has lasted until now.
void writeEpisodes(config::JsonWriter& w, const chain::ActuatorDriver& driver, double now_s) {
  w.beginArray();
  for (const auto& e : driver.episodes())
    w.beginArray().fixed(e[0], 4).fixed(e[1], 3).fixed(e[2] < 0 ? (now_s - e[0]) * 1e3 : e[2], 1).endArray();
  w.endArray();
}

// Each miss judged against the machine's stalls (services/runtime/stall_probe.hpp).
void writeStalls(config::JsonWriter& w, const StallProbe& probe, const chain::ActuatorDriver& driver) {
  const std::int64_t timeout_ns = driver.watchdogTimeoutNs();
  std::uint64_t explained = 0;
  std::vector<double> stalled_ms;
  for (const std::int64_t deadline : driver.missedDeadlinesNs()) {
    const std::int64_t stalled = probe.stalledWhileWaitingNs(deadline, timeout_ns);
    if (StallProbe::explainsMiss(stalled, timeout_ns)) ++explained;
    stalled_ms.push_back(static_cast<double>(stalled) * 1e-6);
  }
  const std::uint64_t misses = driver.watchdog().deadlineMisses();
  w.key("cpu_stalls").beginObject().field("probe_cpus", probe.cpus()).field("fifo", probe.realtimePriority());
  w.field("count", probe.stalls()).fixedField("max_ms", probe.maxStallMs(), 3).fixedField("total_ms", probe.totalStallMs(), 3);
  w.key("windows_ns").beginArray();
  for (const auto& [from, to] : probe.stallWindows()) w.beginArray().value(from).value(to).endArray();
  w.endArray().endObject();
  w.field("deadline_misses_during_cpu_stalls", explained).field("deadline_misses_unexplained", misses - explained);
  w.key("miss_cpu_stalled_ms").beginArray();
  for (const double ms : stalled_ms) w.fixed(ms, 3);
  w.endArray();
}

}  // namespace

std::string simSummaryJson(const SimRun& r) {
  std::lock_guard<std::mutex> lock(r.link.mutex());
  const auto& driver = r.link.driver();
  const auto& watchdog = driver.watchdog();
  const auto& monitor = r.node.monitor();
  const auto& sim = r.node.simulator();
  const auto& stats = sim.stats();
  config::JsonWriter w;
  w.beginObject().field("service", "mft-sim").field("scenario", r.ctx.scenario().name);
  w.field("mode", r.ctx.lockstep() ? "lockstep" : "realtime").field("fell", monitor.fell());
  w.fixedField("fall_time_s", monitor.fallTime(), 4).field("fall_reason", monitor.fallReason());
  w.field("ticks", sim.tick()).fixedField("sim_time_s", sim.time(), 4).fixedField("wall_time_s", r.wall_s, 3);
  w.fixedField("start_wait_s", r.start_wait_s, 3).fixedField("real_time_factor", sim.time() / std::max(r.wall_s, 1e-9), 3);
  w.field("deadline_misses", watchdog.deadlineMisses()).field("lost_commands", watchdog.lostCommands());
  w.field("damping_ticks", driver.dampingTicks()).field("startup_ticks", driver.startupTicks());
  w.field("lockstep_resends", r.resends).field("watchdog_recoveries", watchdog.recoveries());
  writeDeadlineFields(w, r.link.deadlineCounts(), "reader_");
  w.key("base_height_error_m").beginObject().fixedField("rms", monitor.heightError().rms(), 6);
  w.fixedField("max", monitor.heightError().max_abs, 6).endObject();
  w.key("pitch_error_rad").beginObject().fixedField("rms", monitor.pitchError().rms(), 6);
  w.fixedField("max", monitor.pitchError().max_abs, 6).endObject();
  w.fixedField("average_speed_mps", monitor.averageSpeed(), 5).fixedField("distance_m", monitor.distance(), 5);
  w.fixedField("final_base_height_m", sim.groundTruth().q[1], 5).field("impulses_applied", stats.impulses.size());
  w.field("max_closure_error_m", stats.max_closure_error_m, 3);
  w.key("touchdowns").beginArray().value(stats.touchdowns[0]).value(stats.touchdowns[1]).endArray();
  w.field("body_contact_steps", stats.body_contact_steps);
  w.key("first_body_contact").raw(chain::bodyContactJson(stats.first_body_contact));
  w.field("error", r.error).field("commands_received", driver.commandsReceived());
  w.key("commands_rejected").beginObject().field("nonfinite", driver.refused(chain::InputVerdict::NonFinite));
  w.field("out_of_range", driver.refused(chain::InputVerdict::OutOfRange));
  w.field("bad_mode", driver.refused(chain::InputVerdict::BadEnum)).endObject();
  r.pushes.writeCounts(w);
  w.field("recorder_window", r.recorder.window()).field("recorder_waits", r.recorder.waits());
  w.fixedField("recorder_wait_s", r.recorder.waitSeconds(), 3).field("recorder_complete", r.recorder_complete);
  w.key("profiles").raw(chain::profilesJson(r.ctx.profileNames()));
  w.key("topic_pushes_applied");
  r.pushes.writeApplied(w);
  w.key("damping_episodes");
  writeEpisodes(w, driver, sim.time());
  w.key("recovery").raw(r.node.recoveryJson());
  w.key("latency_us").raw(r.link.latencyUs().json());
  w.key("watchdog_detection_after_deadline_ms").raw(r.detection_ms.json());
  r.pacer.writeFields(w);
  if (r.stall_probe) writeStalls(w, *r.stall_probe, driver);
  return w.endObject().str();
}

}  // namespace mft::services
