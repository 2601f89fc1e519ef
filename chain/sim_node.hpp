#pragma once
// The simulator stage of the chain: the ODE world started at the scenario's pose, the scenario's pushes, and
// after every step the run monitor (fall, tracking) and the push-recovery window. Tick k: step(command(k))
// takes the world from sensors(k) to sensors(k + 1). mft-sim and mft-closedloop drive it the same way.
#include <cstddef>
#include <cstdint>
#include <string>

#include "chain/push_recovery.hpp"
#include "chain/push_schedule.hpp"
#include "chain/run_monitor.hpp"
#include "chain/scenario.hpp"
#include "sim/simulator.hpp"

namespace mft::chain {

// The scenario's initial pose: its base height and stance width, right foot ahead (0: both under the hip).
sim::StandingPose initialPose(const Scenario& scenario);
FallCriteria fallCriteria(const Scenario& scenario);

class SimNode {
 public:
  // Throws std::invalid_argument when the scenario's initial pose cannot be built on `terrain`.
  // `settle_time_s`: the run monitor's tracking statistics start there.
  SimNode(const model::RobotDescription& robot, const sim::SimOptions& options, const sim::Terrain& terrain,
          const Scenario& scenario, double settle_time_s);

  // One control period with `command`: arms the due scenario pushes (`gait`: the planner's phase this tick, for
  // pushes at a gait phase), steps, then updates the monitor and the recovery window. Returns true at the first
  // fall. Never allocates (beyond the simulator's impulse log).
  bool step(const model::ActuatorCommand& command, const GaitPhase& gait = {});
  const ScenarioPushes& pushes() const { return pushes_; }
  // A push from outside the scenario (an operator's), applied by the simulator's rule for its trigger.
  void schedule(const sim::ImpulseSpec& push) { sim_.scheduleImpulse(push); }

  // The ticks the scenario's duration covers.
  std::uint64_t ticksTotal() const { return ticks_total_; }
  std::uint64_t tick() const { return sim_.tick(); }
  double time() const { return sim_.time(); }
  const sim::Simulator& simulator() const { return sim_; }
  const model::SensorReadings& sensors() const { return sim_.sensors(); }
  const model::GroundTruthState& truth() const { return sim_.groundTruth(); }
  const RunMonitor& monitor() const { return monitor_; }
  const RecoveryWindow& recovery() const { return recovery_; }
  // The impulses applied by the last step(): simulator().stats().impulses[first, end).
  std::size_t firstNewImpulse() const { return first_new_impulse_; }
  // The recovery record and verdict under the scenario's criteria (the summaries' "recovery" section).
  RecoveryVerdict recoveryVerdict() const;
  std::string recoveryJson() const;

 private:
  const Scenario& scenario_;
  sim::Terrain terrain_;
  sim::Simulator sim_;
  ScenarioPushes pushes_;
  RunMonitor monitor_;
  RecoveryWindow recovery_;
  std::uint64_t ticks_total_ = 0;
  std::size_t first_new_impulse_ = 0, recovery_impulses_ = 0;
};

// The simulator's first non-foot terrain contact as JSON (the summaries' "first_body_contact"): body, time_s,
// x_m, z_m, normal_x, normal_z, depth_m; null when there was none.
std::string bodyContactJson(const sim::BodyContact& contact);

}  // namespace mft::chain
