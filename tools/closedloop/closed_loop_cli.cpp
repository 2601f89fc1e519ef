#include "tools/closedloop/closed_loop_cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "chain/scenario_limits.hpp"
#include "common/install_layout.hpp"
#include "common/strict_yaml.hpp"

namespace mft::closedloop {

void declareOptions(config::CommandLine& cli) {
  cli.option("scenario", "scenario file (config/scenarios/*.yaml)");
  cli.option("config-dir", "configuration folder", config::configDirFor(MFT_CONFIG_DIR));
  cli.option("profile", "configuration profile config/profiles/NAME.yaml, applied after the scenario's "
             "(repeatable, in order, or a comma list; docs/guide/profiles.md)");
  cli.option("controller", "mft | sa | none (default: the scenario's, else mft)");
  cli.option("estimator", "kalman | ground_truth (default: the scenario's, else kalman)");
  cli.option("height", "base height command and initial height [m] (default 0.42 without a scenario)");
  cli.option("speed", "average speed command [m/s] (walk when != 0)");
  cli.option("duration", "run length [s] (default 10 without a scenario)");
  cli.option("step-at", "without --scenario: when stepping starts [s]", "1.0");
  cli.flag("stand", "without --scenario: stand only, never step");
  cli.option("push", "a sagittal push on the torso [N s] (+ forward)");
  cli.option("push-at", "the push is armed at this time [s] and lands at the next right-foot lift-off", "5.0");
  cli.flag("push-timed", "apply the push at --push-at itself instead of at a lift-off");
  cli.flag("no-scenario-profiles", "ignore the scenario file's profiles (e.g. the paper's setup on terrain-course, "
           "whose file carries kv-0.145); --profile values still apply");
  cli.option("stance-width", "initial distance between the feet [m], right foot ahead (default: the scenario's "
             "initial_stance_width_m; without --scenario 0.12 with --stand, else 0)");
  cli.option("recovery-rule", "what counts as recovered from a push: stepping (back to stepping in place) | "
             "no_fall (default: the scenario's, else stepping); both outcomes are always in --json's \"recovery\"");
  cli.option("stats-from", "statistics window start [s]", "2.0");
  cli.flag("continue-after-fall", "keep running after a fall");
  cli.option("csv", "write a per-tick trace to this CSV file");
  cli.option("csv-every", "write every n-th tick to the CSV", "1");
  cli.option("trajectory", "write the full-precision trajectory (truth of tick k, command k) to this CSV file");
  cli.flag("json", "print the summary as JSON (default: a short text summary)");
  cli.option("dump-qp", "write the WBC's QP of the ticks in the dump window to this existing folder as WBCQP files "
             "(docs/reference/qp-instances.md)");
  cli.option("dump-from", "with --dump-qp: first tick of the window, as sim time [s]", "0.0");
  cli.option("dump-count", "with --dump-qp: number of consecutive ticks", "1");
  cli.option("dump-name", "with --dump-qp: instance name prefix; files are <prefix>_<tick>.txt", "wbc");
}

namespace {

// Values given on the command line override a scenario file's.
void overrideScenario(const config::CommandLine& cli, chain::Scenario& scenario) {
  if (cli.isSet("height")) {
    const double h = cli.getDouble("height", 0.1, 1.0);
    scenario.initial_base_height_m = h;
    for (auto& c : scenario.commands) c.z_cmd_m = h;
  }
  if (cli.isSet("speed")) {
    const double v = cli.getDouble("speed", -3.0, 3.0);
    for (auto& c : scenario.commands)
      if (c.mode == chain::LocomotionMode::Walk) c.v_cmd_mps = v;
  }
  if (cli.isSet("duration")) scenario.duration_s = cli.getDouble("duration", 0.001, 3600.0);
}

}  // namespace

chain::Scenario scenarioFromOptions(const config::CommandLine& cli, Configs* configs_out) {
  Configs& configs = *configs_out;
  chain::Scenario scenario;
  try {
    if (cli.isSet("scenario")) {
      scenario = chain::loadScenario(cli.get("scenario"));
      if (cli.isSet("no-scenario-profiles")) scenario.profiles.clear();
    } else {
      const double h = cli.isSet("height") ? cli.getDouble("height", 0.1, 1.0) : 0.42;
      const double v = cli.isSet("speed") ? cli.getDouble("speed", -3.0, 3.0) : 0.0;
      const double d = cli.isSet("duration") ? cli.getDouble("duration", 0.001, 3600.0) : 10.0;
      scenario = makeScenario(h, v, d, "mft", "kalman", cli.getDouble("step-at", 0.0, 3600.0), cli.isSet("stand"));
    }
    scenario.profiles = chain::runProfiles(scenario, cli.getAll("profile"));
    configs = loadConfigs(cli.get("config-dir"), scenario.profiles);
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (cli.isSet("scenario")) overrideScenario(cli, scenario);
  if (cli.isSet("controller")) scenario.controller = cli.get("controller");
  if (cli.isSet("estimator")) scenario.estimator = cli.get("estimator");
  if (scenario.controller != "mft" && scenario.controller != "sa" && scenario.controller != "none")
    cli.fail("--controller: expected mft, sa or none");
  if (scenario.estimator != "kalman" && scenario.estimator != "ground_truth")
    cli.fail("--estimator: expected kalman or ground_truth");
  if (cli.isSet("push")) {
    chain::ScenarioPush p;
    p.impulse_Ns = cli.getDouble("push", -100.0, 100.0);
    p.at_s = cli.getDouble("push-at", 0.0, 3600.0);
    p.at_liftoff_leg = cli.isSet("push-timed") ? -1 : 0;
    scenario.pushes.push_back(p);
  }

  if (cli.isSet("recovery-rule") && !chain::parseRecoveryRule(cli.get("recovery-rule"), &scenario.recovery.rule))
    cli.fail("--recovery-rule: expected stepping or no_fall");
  if (cli.isSet("stance-width")) scenario.initial_stance_width_m = cli.getDouble("stance-width", 0.0, 0.4);
  // As the stack does (mft-sim --check-scenario): the start pose in the legs' reach, the commands inside
  // what the planner accepts.
  try {
    chain::checkScenarioLimits(scenario, configs.robot,
                               planner::commandLimits(configs.robot, configs.planner.command, configs.planner.source_file));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  return scenario;
}

TickOutputs::TickOutputs(const config::CommandLine& cli, const Configs& configs) {
  every_ = cli.getInt("csv-every", 1, 1000000);
  if (cli.isSet("csv")) {
    csv_.open(cli.get("csv"));
    if (!csv_) cli.fail("cannot write " + cli.get("csv"));
    csv_ << ClosedLoop::csvHeader() << "\n";
  }
  if (cli.isSet("trajectory")) {
    trajectory_.open(cli.get("trajectory"));
    if (!trajectory_) cli.fail("cannot write " + cli.get("trajectory"));
    trajectory_ << ClosedLoop::trajectoryHeader() << "\n";
  }
  // QP dump window in ticks; writing files is fine here: this loop runs on the sim clock, not in real time.
  dump_ = cli.isSet("dump-qp");
  dump_dir_ = cli.get("dump-qp");
  dump_name_ = cli.get("dump-name");
  if (dump_) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dump_dir_, ec)) cli.fail("--dump-qp: not a folder: " + dump_dir_);
    if (dump_name_.empty() || dump_name_.find('/') != std::string::npos) cli.fail("--dump-name: expected a plain name");
    dump_first_ = static_cast<std::uint64_t>(
        std::llround(cli.getDouble("dump-from", 0.0, 3600.0) / configs.sim.control_period_s));
    dump_end_ = dump_first_ + static_cast<std::uint64_t>(cli.getInt("dump-count", 1, 100000));
  }
}

void TickOutputs::onTick(const ClosedLoop& l) {
  if (csv_.is_open() && n_++ % every_ == 0) csv_ << l.csvRow() << "\n";
  if (trajectory_.is_open()) trajectory_ << l.trajectoryRow() << "\n";
  if (dump_ && dump_error_.empty() && l.controller().hasLastProblem()) dumpQp(l.controller());
}

void TickOutputs::dumpQp(const wbc::WholeBodyController& c) {
  const std::uint64_t tick = c.lastProblemTick();
  if (tick < dump_first_ || tick >= dump_end_ || tick < dump_first_ + dumped_) return;
  char name[160];
  std::snprintf(name, sizeof name, "%s_%05llu", dump_name_.c_str(), static_cast<unsigned long long>(tick));
  try {
    c.writeLastQp(dump_dir_ + "/" + name + ".txt", name);
    dumped_ = tick - dump_first_ + 1;
  } catch (const std::exception& e) {
    dump_error_ = e.what();
  }
}

void TickOutputs::finish(const config::CommandLine& cli) const {
  if (!dump_error_.empty()) cli.fail("--dump-qp: " + dump_error_);
  if (dump_ && dumped_ < dump_end_ - dump_first_)
    cli.fail("--dump-qp: the run ended before the dump window did (" + std::to_string(dumped_) + " of " +
             std::to_string(dump_end_ - dump_first_) + " ticks written)");
}

void printTextSummary(const chain::Scenario& scenario, const RunSummary& s, const ClosedLoop& loop, double stats_from_s) {
  std::printf("%s (%s, %s estimator%s%s): %s after %.3f s%s%s\n", scenario.name.c_str(), scenario.controller.c_str(),
              scenario.estimator.c_str(), scenario.profiles.empty() ? "" : ", profiles ",
              scenario.profiles.empty() ? "" : chain::profilesJson(scenario.profiles).c_str(), s.fell ? "FELL" : "ok", s.fell ? s.fall_time_s : s.sim_time_s,
              s.fell ? ": " : "", s.fall_reason.c_str());
  // An empty statistics window (the run ended before --stats-from) has no figures: n/a, not placeholders.
  const bool have = s.window_samples > 0;
  auto stat = [&](double v, int decimals) {
    char buf[32];
    if (!have) return std::string("n/a");
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return std::string(buf);
  };
  if (!have)
    std::printf("  window empty: the run ended before the statistics window began at %.1f s (--stats-from): "
                "no window figures\n", stats_from_s);
  std::printf("  window %.1f s: base z mean %s m [%s, %s], rms error %s m; pitch rms %s max %s rad\n", s.window_s,
              stat(s.mean_base_z, 4).c_str(), stat(s.min_base_z, 4).c_str(), stat(s.max_base_z, 4).c_str(),
              stat(s.rms_base_z_error, 4).c_str(), stat(s.rms_pitch, 4).c_str(), stat(s.max_abs_pitch, 4).c_str());
  std::printf("  average speed %s m/s; steps %llu (early %llu, late %llu, forced %llu); estimator rms z %s m, "
              "pitch %s rad, vx %s m/s\n",
              stat(s.average_speed, 4).c_str(), static_cast<unsigned long long>(s.steps),
              static_cast<unsigned long long>(s.early_touchdowns), static_cast<unsigned long long>(s.late_touchdowns),
              static_cast<unsigned long long>(s.forced_touchdowns), stat(s.est_rms_z, 4).c_str(),
              stat(s.est_rms_pitch, 4).c_str(), stat(s.est_rms_vx, 4).c_str());
  std::printf("  max MFT violation %s rad, min LTI %s; non-optimal solves %llu, torque clamped %llu; "
              "%.1fx real time\n",
              stat(s.max_mft_violation, 4).c_str(), stat(s.min_lti, 3).c_str(),
              static_cast<unsigned long long>(s.non_optimal_solves),
              static_cast<unsigned long long>(s.torque_clamped_ticks), s.sim_time_s / std::max(s.wall_time_s, 1e-9));
  if (!scenario.pushes.empty()) {
    const auto v = loop.recoveryVerdict();
    std::printf("  push: %s (%s; rule %s)\n", v.recovered ? "RECOVERED" : "NOT RECOVERED", v.reason.c_str(),
                chain::toString(scenario.recovery.rule));
  }
}

}  // namespace mft::closedloop
