#include "chain/closed_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/json_writer.hpp"
#include "common/profiles.hpp"

namespace mft::closedloop {
namespace {

double wallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

sim::Terrain terrainOf(const Configs& configs, const chain::Scenario& scenario, const RunOptions& options) {
  return options.terrain ? *options.terrain : sim::loadTerrain(configs.config_dir + "/terrain/" + scenario.terrain + ".yaml");
}

}  // namespace

Configs loadConfigs(const std::string& dir, const std::vector<std::string>& profiles) {
  const config::ScopedProfiles scoped(config::ProfileSet::load(dir, profiles));
  Configs c;
  c.config_dir = dir;
  c.profiles = profiles;
  c.robot = model::loadRobotDescription(dir + "/robot.yaml");
  c.sim = sim::loadSimOptions(dir + "/sim.yaml");
  c.estimator = estimator::loadEstimatorConfig(dir + "/estimator.yaml");
  c.planner = planner::loadPlannerConfig(dir + "/planner.yaml");
  c.wbc = wbc::loadWbcConfig(dir + "/wbc.yaml");
  c.polytope = model::loadMftPolytope(dir + "/mft_space.yaml", c.robot);
  return c;
}

chain::Scenario makeScenario(double height_m, double speed_mps, double duration_s, const std::string& controller,
                                const std::string& estimator, double step_at_s, bool stand_only,
                                double stance_width_m) {
  chain::Scenario s;
  s.name = stand_only ? "stand" : (speed_mps != 0.0 ? "walk" : "step-in-place");
  s.description = "built by mft-closedloop";
  s.duration_s = duration_s;
  s.controller = controller;
  s.estimator = estimator;
  s.terrain = "flat";
  s.initial_base_height_m = height_m;
  s.initial_stance_width_m = stance_width_m >= 0.0 ? stance_width_m : (stand_only ? kStandStanceWidth : 0.0);
  s.fall_base_height_m = 0.25;  // the scenario files' values
  s.fall_pitch_rad = 0.8;
  s.commands.push_back({0.0, chain::LocomotionMode::Stand, height_m, 0.0});
  if (!stand_only)
    s.commands.push_back({step_at_s,
                          speed_mps != 0.0 ? chain::LocomotionMode::Walk : chain::LocomotionMode::StepInPlace,
                          height_m, speed_mps});
  return s;
}

ClosedLoop::ClosedLoop(const Configs& configs, const chain::Scenario& scenario, const RunOptions& options)
    : configs_(configs), scenario_(scenario), options_(options) {
  sim_ = std::make_unique<chain::SimNode>(configs_.robot, configs_.sim, terrainOf(configs_, scenario_, options_), scenario_,
                                          options_.stats_from_s);
  estimator_ = std::make_unique<chain::EstimatorNode>(chain::withScenarioMode(configs_.estimator, scenario_.estimator),
                                                      configs_.robot);
  planner_ = std::make_unique<chain::PlannerNode>(configs_.planner, configs_.robot, scenario_);
  wbc_ = std::make_unique<chain::WbcNode>(configs_.robot, chain::withScenarioController(configs_.wbc, scenario_.controller),
                                          configs_.polytope);
  z_cmd_ = scenario_.commands.front().z_cmd_m;
  summary_.min_base_z = 1e9;
  summary_.max_base_z = -1e9;
  summary_.max_mft_violation = -1e9;
  wall_start_ = wallNow();
}

ClosedLoop::~ClosedLoop() = default;

// Tick k in the lockstep stack's order: estimate(k) -> the scenario's commands due at t_k -> plan(k) ->
// command(k) -> the simulator's step (due pushes armed) -> the fall check on truth(k + 1).
bool ClosedLoop::step() {
  if (finished_) return false;
  if (sim_->tick() >= sim_->ticksTotal()) {
    finished_ = true;
    return false;
  }
  truth_at_estimate_ = sim_->truth();
  estimate_ = estimator_->update(sim_->sensors(), &truth_at_estimate_);
  planner_->applyScenarioCommands(estimate_.time_s, [](const planner::OperatorCommand&, const planner::CommandResult& r) {
    if (!r.accepted) std::fprintf(stderr, "closed loop: command rejected: %s\n", r.reason.c_str());
  });
  const auto& command = wbc_->update(estimate_, planner_->plan(estimate_));
  const auto& plan = planner_->output();
  const bool fell_now = sim_->step(command, {true, plan.step_index, plan.phase, plan.stance_leg});
  // mft-sim's height command for the statistics: the one in force at the new time.
  z_cmd_ = chain::commandedHeight(scenario_, sim_->time());
  accumulate();
  if (fell_now && options_.stop_at_fall) finished_ = true;
  if (sim_->tick() >= sim_->ticksTotal()) finished_ = true;
  return !finished_;
}

void ClosedLoop::accumulate() {
  RunSummary& s = summary_;
  const auto& truth = sim_->truth();
  const auto& monitor = sim_->monitor();
  const auto& diag = wbc_->diagnostics();
  s.ticks = sim_->tick();
  s.sim_time_s = sim_->time();
  s.wall_time_s = wallNow() - wall_start_;
  s.fell = monitor.fell();
  s.fall_time_s = monitor.fallTime();
  s.fall_reason = monitor.fallReason();
  s.body_contact_steps = sim_->simulator().stats().body_contact_steps;
  s.first_body_contact = sim_->simulator().stats().first_body_contact;
  if (diag.qp_attempted && diag.status != qp::QpStatus::Optimal) ++s.non_optimal_solves;
  if (diag.safety_event != wbc::SafetyEvent::None) ++s.safety_events;
  if (diag.torque_clamped) ++s.torque_clamped_ticks;
  const auto& plan = planner_->output();
  if (plan.step_index != last_step_seen_) {
    if (last_step_seen_ > 0) {
      switch (plan.last_touchdown) {
        case planner::TouchdownKind::Forced: ++s.forced_touchdowns; break;
        case planner::TouchdownKind::Late: ++s.late_touchdowns; break;
        case planner::TouchdownKind::Early: ++s.early_touchdowns; break;
        default: break;
      }
    }
    last_step_seen_ = plan.step_index;
  }
  s.steps = plan.step_index;
  s.final_base_x = truth.q[model::kBaseX];
  s.max_base_x = s.ticks <= 1 ? s.final_base_x : std::max(s.max_base_x, s.final_base_x);

  // The window: statistics of the truth after the tick, and of the estimate the controller used against the
  // truth it was computed from.
  const double t = sim_->time();
  if (t < options_.stats_from_s - 1e-9 || monitor.fell()) return;
  if (n_window_ == 0) {
    window_x0_ = truth.q[model::kBaseX];
    window_t0_ = t;
  }
  ++n_window_;
  const double z = truth.q[model::kBaseZ], p = truth.q[model::kBasePitch];
  sum_z_ += z;
  sum_ez2_ += (z - z_cmd_) * (z - z_cmd_);
  sum_p2_ += p * p;
  const auto& tr = truth_at_estimate_;
  const double ez = estimate_.q[model::kBaseZ] - tr.q[model::kBaseZ];
  const double ep = estimate_.q[model::kBasePitch] - tr.q[model::kBasePitch];
  const double ev = estimate_.qd[model::kBaseX] - tr.qd[model::kBaseX];
  sum_est_z2_ += ez * ez;
  sum_est_p2_ += ep * ep;
  sum_est_vx2_ += ev * ev;
  const double n = static_cast<double>(n_window_);
  s.window_samples = n_window_;
  s.window_s = t - window_t0_;
  s.mean_base_z = sum_z_ / n;
  s.rms_base_z_error = std::sqrt(sum_ez2_ / n);
  s.max_abs_base_z_error = std::max(s.max_abs_base_z_error, std::abs(z - z_cmd_));
  s.rms_pitch = std::sqrt(sum_p2_ / n);
  s.max_abs_pitch = std::max(s.max_abs_pitch, std::abs(p));
  s.min_base_z = std::min(s.min_base_z, z);
  s.max_base_z = std::max(s.max_base_z, z);
  s.average_speed = s.window_s > 0 ? (truth.q[model::kBaseX] - window_x0_) / s.window_s : 0.0;
  s.est_rms_z = std::sqrt(sum_est_z2_ / n);
  s.est_rms_pitch = std::sqrt(sum_est_p2_ / n);
  s.est_rms_vx = std::sqrt(sum_est_vx2_ / n);
  model::VectorA qa;
  for (int i = 0; i < model::kNa; ++i) qa[i] = truth.q[model::kActuatedIndex[i]];
  s.max_mft_violation = std::max(s.max_mft_violation, configs_.polytope.violation(qa));
  s.min_lti = std::min({s.min_lti, truth.lti[0], truth.lti[1]});
}

const RunSummary& ClosedLoop::run(const std::function<void(const ClosedLoop&)>& each_tick) {
  while (step())
    if (each_tick) each_tick(*this);
  if (each_tick && sim_->tick() > 0 && finished_) each_tick(*this);
  return summary_;
}

chain::RecoveryVerdict ClosedLoop::recoveryVerdict() const { return sim_->recoveryVerdict(); }

std::string ClosedLoop::recoveryJson() const { return sim_->recoveryJson(); }

std::string RunSummary::toJson() const {
  // Window figures are null when the window holds no sample (the run ended before it began): their
  // initial values are placeholders, not measurements.
  constexpr int kDigits = 6;
  config::JsonWriter w;
  const auto stat = [&](const char* key, double v) {
    w.key(key);
    if (window_samples) w.value(v, kDigits);
    else w.null();
  };
  w.beginObject().field("fell", fell).field("fall_time_s", fall_time_s, kDigits).field("fall_reason", fall_reason);
  w.field("ticks", ticks).field("sim_time_s", sim_time_s, kDigits).field("wall_time_s", wall_time_s, kDigits);
  w.field("window_s", window_s, kDigits).field("window_samples", window_samples);
  stat("mean_base_z_m", mean_base_z);
  stat("min_base_z_m", min_base_z);
  stat("max_base_z_m", max_base_z);
  stat("rms_base_z_error_m", rms_base_z_error);
  stat("max_abs_base_z_error_m", max_abs_base_z_error);
  stat("rms_pitch_rad", rms_pitch);
  stat("max_abs_pitch_rad", max_abs_pitch);
  stat("average_speed_mps", average_speed);
  w.field("final_base_x_m", final_base_x, kDigits).field("max_base_x_m", max_base_x, kDigits);
  w.key("estimator_rms_error").beginObject();
  stat("z_m", est_rms_z);
  stat("pitch_rad", est_rms_pitch);
  stat("vx_mps", est_rms_vx);
  w.endObject();
  stat("max_mft_violation", max_mft_violation);
  stat("min_lti", min_lti);
  w.field("steps", steps).key("touchdowns").beginObject().field("early", early_touchdowns).field("late", late_touchdowns);
  w.field("forced", forced_touchdowns).endObject().field("non_optimal_solves", non_optimal_solves);
  w.field("safety_events", safety_events).field("torque_clamped_ticks", torque_clamped_ticks);
  w.field("body_contact_steps", body_contact_steps);
  w.key("first_body_contact").raw(chain::bodyContactJson(first_body_contact));
  return w.endObject().str();
}

std::string ClosedLoop::csvHeader() {
  return "t,x,z,pitch,vx,vz,pitch_rate,q4,q5,q6,q7,q8,q9,q10,q11,est_x,est_z,est_pitch,est_vx,est_vz,"
         "z_ref,pitch_ref,z_cmd,stance_leg,phase,step,swing_extended,ref_stance_r,ref_stance_l,"
         "foot_ref_rx,foot_ref_rz,foot_ref_lx,foot_ref_lz,foot_rx,foot_rz,foot_lx,foot_lz,"
         "contact_r,contact_l,est_contact_r,est_contact_l,fz_r,fz_l,fx_r,fx_l,qp_fz_r,qp_fz_l,"
         "tau0,tau1,tau2,tau3,qp_status,slack,mft_violation,lti_r,lti_l,target_x,"
         "sea0,sea1,sea2,sea3,motor_tau0,motor_tau1,motor_tau2,motor_tau3,motor_w0,motor_w1,motor_w2,motor_w3";
}

std::string ClosedLoop::trajectoryHeader() {
  return "tick,x,z,pitch,q4,q5,q6,q7,q8,q9,q10,q11,tau_q4,tau_q6,tau_q8,tau_q10";
}

std::string ClosedLoop::trajectoryRow() const {
  std::string row = std::to_string(truth_at_estimate_.tick);
  char v[32];
  for (int i = 0; i < model::kNq; ++i) {
    std::snprintf(v, sizeof v, ",%.17g", truth_at_estimate_.q[i]);
    row += v;
  }
  for (int i = 0; i < model::kNa; ++i) {
    std::snprintf(v, sizeof v, ",%.17g", wbc_->command().tau[i]);
    row += v;
  }
  return row;
}

std::string ClosedLoop::csvRow() const {
  const auto& tr = truth_at_estimate_;
  const auto& e = estimate_;
  const auto& p = planner_->output();
  const auto& reference = planner_->reference();
  const auto& diag = wbc_->diagnostics();
  const auto& sim = sim_->simulator();
  std::ostringstream o;
  o.precision(7);
  o << tr.time_s;
  for (int i = 0; i < 6; ++i) o << ',' << (i < 3 ? tr.q[i] : tr.qd[i - 3]);
  for (int i = 3; i < model::kNq; ++i) o << ',' << tr.q[i];
  o << ',' << e.q[0] << ',' << e.q[1] << ',' << e.q[2] << ',' << e.qd[0] << ',' << e.qd[1];
  o << ',' << reference.base_z.pos << ',' << reference.base_pitch.pos << ',' << z_cmd_;
  o << ',' << p.stance_leg << ',' << p.phase << ',' << p.step_index << ',' << (p.swing_extended ? 1 : 0);
  o << ',' << reference.foot_in_stance[0] << ',' << reference.foot_in_stance[1];
  for (int i = 0; i < model::kNc; ++i) o << ',' << reference.foot_pos[i];
  const auto& md = wbc_->controller().modelData();  // the controller's model at the estimate
  for (int i = 0; i < model::kNc; ++i) o << ',' << md.foot_pos[i];
  o << ',' << (tr.contact_force[1] > configs_.sim.contact_switch_threshold_N) << ','
    << (tr.contact_force[3] > configs_.sim.contact_switch_threshold_N);
  o << ',' << e.contact[0] << ',' << e.contact[1];
  o << ',' << tr.contact_force[1] << ',' << tr.contact_force[3] << ',' << tr.contact_force[0] << ','
    << tr.contact_force[2];
  o << ',' << diag.f_c[1] << ',' << diag.f_c[3];
  for (int i = 0; i < model::kNa; ++i) o << ',' << wbc_->command().tau[i];
  o << ',' << static_cast<int>(diag.status) << ',' << diag.slack_norm << ',' << diag.mft_violation;
  o << ',' << tr.lti[0] << ',' << tr.lti[1] << ',' << p.target_x;
  // The actuators over the last step: the spring torque on the hips, the drive's torque and speed.
  const model::VectorA sea = sim.seaTorque(), motor = sim.motorTorque(), speed = sim.motorSpeed();
  for (const auto* v : {&sea, &motor, &speed})
    for (int i = 0; i < model::kNa; ++i) o << ',' << (*v)[i];
  return o.str();
}

}  // namespace mft::closedloop
