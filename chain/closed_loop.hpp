#pragma once
// In-process closed loop (issue 6): simulator -> estimator -> planner -> WBC -> simulator, all on the sim clock
// in one thread: the control chain's nodes (chain/) that the DDS services drive over topics, with the same
// configs, scenario, reference mapping and fall criteria. A tuning and test bench: deterministic, about 10-30x
// faster than real time, no processes. Not the product path (that is services/).
//
// Tick k, as in the lockstep stack: sensors(k) [+ truth(k)] -> estimate(k) -> scenario commands due at t_k ->
// plan(k) -> reference(k) -> command(k) -> pushes armed by t_k -> sim.step() -> fall check on truth(k + 1).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "chain/estimator_node.hpp"
#include "chain/planner_node.hpp"
#include "chain/scenario.hpp"
#include "chain/sim_node.hpp"
#include "chain/wbc_node.hpp"
#include "model/mft_polytope.hpp"
#include "model/robot_description.hpp"
#include "sim/sim_options.hpp"
#include "sim/simulator.hpp"
#include "sim/terrain.hpp"
#include "wbc/wbc_config.hpp"

namespace mft::closedloop {

// Every configuration a run needs, loaded from one config folder (the same files the services read).
struct Configs {
  std::string config_dir;
  std::vector<std::string> profiles;  // config/profiles/ applied, in order (docs/guide/profiles.md)
  model::RobotDescription robot;
  sim::SimOptions sim;
  estimator::EstimatorConfig estimator;
  planner::PlannerConfig planner;
  wbc::WbcConfig wbc;
  model::MftPolytope polytope;
};
// Throws config::ConfigError (naming file and key) like the services do at start-up. `profiles` are applied
// to these loads only (the process's active profiles are restored afterwards).
Configs loadConfigs(const std::string& config_dir, const std::vector<std::string>& profiles = {});

// A scenario built from a few numbers (no file): stand at `height_m` until `step_at_s`, then step in place
// (speed 0) or walk (speed != 0) for the rest of `duration_s`. The initial stance width (the scenario's
// initial_stance_width_m, as mft-sim uses it) is kStandStanceWidth for a stand-only scenario (like
// config/scenarios/stand.yaml), else 0 (both feet under the hip axis); a negative stance_width_m means that default.
constexpr double kStandStanceWidth = 0.12;
chain::Scenario makeScenario(double height_m, double speed_mps, double duration_s, const std::string& controller,
                                const std::string& estimator, double step_at_s = 1.0, bool stand_only = false,
                                double stance_width_m = -1.0);

struct RunOptions {
  bool stop_at_fall = true;
  // Statistics (the summary below) are taken over [stats_from_s, end]; the RunMonitor's settle time too.
  double stats_from_s = 2.0;
  // Replaces the scenario's terrain file (a diagnosis: e.g. the course with one obstacle removed, built from the
  // course file in a test); unset = config_dir/terrain/<scenario.terrain>.yaml, as mft-sim loads it.
  std::optional<sim::Terrain> terrain;
};

// Running figures over the statistics window (ground truth unless named estimator).
struct RunSummary {
  bool fell = false;
  double fall_time_s = 0.0;
  std::string fall_reason;
  std::uint64_t ticks = 0;
  double sim_time_s = 0.0, wall_time_s = 0.0;
  double window_s = 0.0;               // length of the statistics window covered so far
  std::uint64_t window_samples = 0;    // ticks in it; 0: the figures below are undefined (printed n/a, JSON null)
  double mean_base_z = 0.0;            // [m]
  double rms_base_z_error = 0.0;       // vs the commanded height [m]
  double max_abs_base_z_error = 0.0;
  double rms_pitch = 0.0, max_abs_pitch = 0.0;  // [rad]
  double min_base_z = 0.0, max_base_z = 0.0;
  double average_speed = 0.0;          // (x_end - x_start) / window [m/s]
  double final_base_x = 0.0, max_base_x = 0.0;  // world x of the base at the last tick, and its largest, whole run
                                                // (how far a terrain run got) [m]
  double est_rms_z = 0.0, est_rms_pitch = 0.0, est_rms_vx = 0.0;  // estimate - truth
  double max_mft_violation = 0.0;      // max over the window of max(A q_a - b) (truth; NaN without polytope)
  double min_lti = 1.0;
  std::uint64_t steps = 0;             // planner lift-offs
  std::uint64_t non_optimal_solves = 0, safety_events = 0, torque_clamped_ticks = 0;
  std::uint64_t body_contact_steps = 0;
  sim::BodyContact first_body_contact;  // which body touched the terrain first, when and where
  std::uint64_t forced_touchdowns = 0, late_touchdowns = 0, early_touchdowns = 0;
  std::string toJson() const;
};

class ClosedLoop {
 public:
  ClosedLoop(const Configs& configs, const chain::Scenario& scenario, const RunOptions& options = {});
  ~ClosedLoop();

  // One control tick. Returns false once the run is over (duration reached, or a fall with stop_at_fall).
  bool step();
  // Runs to the end; `each_tick` (may be empty) is called after every tick.
  const RunSummary& run(const std::function<void(const ClosedLoop&)>& each_tick = {});
  bool finished() const { return finished_; }

  const RunSummary& summary() const { return summary_; }
  const chain::Scenario& scenario() const { return scenario_; }
  const Configs& configs() const { return configs_; }
  const sim::Simulator& simulator() const { return sim_->simulator(); }
  const estimator::StateEstimator& estimator() const { return estimator_->estimator(); }
  const planner::MotionPlanner& planner() const { return planner_->planner(); }
  const wbc::WholeBodyController& controller() const { return wbc_->controller(); }
  const chain::RunMonitor& monitor() const { return sim_->monitor(); }
  // The push-recovery record and verdict (chain/push_recovery.hpp) under the scenario's criteria,
  // exactly as mft-sim reports them in its summary's "recovery" section.
  const chain::RecoveryWindow& recoveryWindow() const { return sim_->recovery(); }
  chain::RecoveryVerdict recoveryVerdict() const;
  std::string recoveryJson() const;
  // This tick's data (valid after the first step()): what the controller saw and did.
  const model::RobotStateEstimate& estimate() const { return estimate_; }
  const model::GroundTruthState& truthAtEstimate() const { return truth_at_estimate_; }
  const planner::PlanOutput& plan() const { return planner_->output(); }
  const wbc::WbcReference& reference() const { return planner_->reference(); }
  const wbc::WbcDiagnostics& diagnostics() const { return wbc_->diagnostics(); }
  const model::ActuatorCommand& command() const { return wbc_->command(); }
  double commandedHeight() const { return z_cmd_; }

  // CSV trace: header() once, then row() per tick (truth, estimate, reference, plan, WBC).
  static std::string csvHeader();
  std::string csvRow() const;
  // The lockstep trajectory at full precision (%.17g), per tick k: the truth of tick k (what mft-sim publishes
  // as GroundTruth(k)) and command(k): tick,x,z,pitch,q4..q11,tau_q4,tau_q6,tau_q8,tau_q10. Compared with a DDS
  // stack's recording of the same scenario (tests/closedloop/test_inprocess_vs_dds.py).
  static std::string trajectoryHeader();
  std::string trajectoryRow() const;

 private:
  void accumulate();

  Configs configs_;
  chain::Scenario scenario_;
  RunOptions options_;
  std::unique_ptr<chain::SimNode> sim_;
  std::unique_ptr<chain::EstimatorNode> estimator_;
  std::unique_ptr<chain::PlannerNode> planner_;
  std::unique_ptr<chain::WbcNode> wbc_;
  bool finished_ = false;
  double z_cmd_ = 0.0;
  model::RobotStateEstimate estimate_;
  model::GroundTruthState truth_at_estimate_;
  planner::TouchdownKind last_touchdown_seen_ = planner::TouchdownKind::None;
  std::uint64_t last_step_seen_ = 0;

  // Window accumulators.
  RunSummary summary_;
  std::uint64_t n_window_ = 0;
  double sum_z_ = 0.0, sum_ez2_ = 0.0, sum_p2_ = 0.0, sum_est_z2_ = 0.0, sum_est_p2_ = 0.0, sum_est_vx2_ = 0.0;
  double window_x0_ = 0.0, window_t0_ = 0.0;
  double wall_start_ = 0.0;
};

}  // namespace mft::closedloop
