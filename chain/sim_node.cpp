#include "chain/sim_node.hpp"

#include <cmath>

#include "chain/command_schedule.hpp"
#include "common/json_writer.hpp"

namespace mft::chain {

sim::StandingPose initialPose(const Scenario& scenario) {
  sim::StandingPose pose;
  pose.base_height_m = scenario.initial_base_height_m;
  pose.foot_offset_x_m = {0.5 * scenario.initial_stance_width_m, -0.5 * scenario.initial_stance_width_m};
  return pose;
}

FallCriteria fallCriteria(const Scenario& scenario) {
  FallCriteria c;
  c.base_height_below_m = scenario.fall_base_height_m;
  c.pitch_beyond_rad = scenario.fall_pitch_rad;
  return c;
}

namespace {
// Resets `simulator` to the scenario's pose first: the pushes must be scheduled after the reset (it drops them).
sim::Simulator& placed(sim::Simulator& simulator, const Scenario& scenario) {
  simulator.reset(initialPose(scenario));
  return simulator;
}
}  // namespace

SimNode::SimNode(const model::RobotDescription& robot, const sim::SimOptions& options, const sim::Terrain& terrain,
                 const Scenario& scenario, double settle_time_s)
    : scenario_(scenario),
      terrain_(terrain),
      sim_(robot, options, terrain_),
      pushes_(scenario.pushes, placed(sim_, scenario)),
      monitor_(fallCriteria(scenario), settle_time_s),
      recovery_(scenario.recovery.window_s, options.control_period_s),
      ticks_total_(static_cast<std::uint64_t>(std::llround(scenario.duration_s / options.control_period_s))) {}

bool SimNode::step(const model::ActuatorCommand& command, const GaitPhase& gait) {
  pushes_.arm(sim_, gait);
  sim_.setCommand(command);
  sim_.step();
  const auto& truth = sim_.groundTruth();
  const auto& stats = sim_.stats();
  const bool fell_now = monitor_.update(truth, commandedHeight(scenario_, sim_.time()), stats.body_contact_steps);
  first_new_impulse_ = recovery_impulses_;
  for (; recovery_impulses_ < stats.impulses.size(); ++recovery_impulses_)
    recovery_.onImpulse(stats.impulses[recovery_impulses_].time_s, stats.impulses[recovery_impulses_].impulse_Ns.x());
  recovery_.update(truth, stats.touchdowns[0] + stats.touchdowns[1]);
  return fell_now;
}

RecoveryVerdict SimNode::recoveryVerdict() const {
  return judgeRecovery(recovery_.record(), scenario_.recovery, monitor_.fell(), monitor_.fallTime(),
                       monitor_.fallReason());
}

std::string SimNode::recoveryJson() const {
  return recovery_.json(scenario_.recovery, monitor_.fell(), monitor_.fallTime(), monitor_.fallReason());
}

std::string bodyContactJson(const sim::BodyContact& b) {
  if (!b.seen) return "null";
  constexpr int kDigits = 6;
  config::JsonWriter w;
  w.beginObject().field("time_s", b.time_s, kDigits).field("body", sim::robotBodyName(b.body));
  w.field("x_m", b.point.x(), kDigits).field("z_m", b.point.y(), kDigits);
  w.field("normal_x", b.normal.x(), kDigits).field("normal_z", b.normal.y(), kDigits);
  return w.field("depth_m", b.depth_m, kDigits).endObject().str();
}

}  // namespace mft::chain
