#pragma once
// Shared by the simulator tests and sim_hash_probe: config loading and the simple stance controller of
// docs/reference/simulation.md#standing-with-a-joint-pd (hip PD + gravity feed-forward -J' (0, W/2) per leg).
#include <string>

#include "model/five_bar.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"
#include "sim/sim_options.hpp"
#include "sim/simulator.hpp"

namespace mft::sim::test {

inline model::RobotDescription robot() { return model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }
inline SimOptions options() { return loadSimOptions(std::string(MFT_CONFIG_DIR) + "/sim.yaml"); }
inline Terrain terrainFile(const std::string& name) {
  return loadTerrain(std::string(MFT_CONFIG_DIR) + "/terrain/" + name);
}

// For the actuator tests (options with fix_torso): resets `sim` with the torso held in the air at base_height_m
// and 0.40 m legs, and drives the right leg's rear and fore hips with constant torques. Returns that command.
inline model::ActuatorCommand hangAndDriveRightHips(Simulator& sim, double base_height_m, double tau_rear,
                                                    double tau_fore) {
  StandingPose pose;
  pose.base_height_m = base_height_m;
  pose.leg_length_m = 0.40;
  sim.reset(pose);
  model::ActuatorCommand c;
  c.tau << tau_rear, tau_fore, 0.0, 0.0;
  sim.setCommand(c);
  return c;
}

// Joint-space PD on the four hips around a fixed target, plus the torque that carries half the weight on
// each foot. Kp >= 300 N m/rad is needed for this geometry (docs/reference/simulation.md#standing-with-a-joint-pd).
struct StanceController {
  model::FiveBarGeometry geometry;
  model::VectorA q_des = model::VectorA::Zero();
  double kp = 300.0, kd = 6.0, leg_load = 0.0;

  StanceController(const model::RobotDescription& d, const model::VectorQ& q_stand, double kp_ = 300.0,
                   double kd_ = 6.0)
      : geometry(model::FiveBarGeometry::from(d)), kp(kp_), kd(kd_), leg_load(0.5 * d.totalMass() * d.gravity_mps2) {
    for (int i = 0; i < model::kNa; ++i) q_des[i] = q_stand[model::kActuatedIndex[static_cast<std::size_t>(i)]];
  }

  model::ActuatorCommand command(const model::SensorReadings& s) const {
    model::ActuatorCommand c;
    c.tick = s.tick;
    for (int leg = 0; leg < model::kNumLegs; ++leg) {
      model::FiveBarPose p;
      const auto ir = static_cast<std::size_t>(2 * leg), jf = static_cast<std::size_t>(2 * leg + 1);
      Eigen::Vector2d ff(0.0, 0.0);
      if (model::fiveBarForward(geometry, s.actuated_pos[ir], s.actuated_pos[jf], &p) == model::FiveBarStatus::Ok)
        ff = -model::fiveBarFootJacobian(geometry, p).transpose() * Eigen::Vector2d(0.0, leg_load);
      for (int k = 0; k < 2; ++k) {
        const auto i = static_cast<std::size_t>(2 * leg + k);
        c.tau[static_cast<int>(i)] = kp * (q_des[static_cast<int>(i)] - s.actuated_pos[i]) - kd * s.actuated_vel[i] + ff[k];
      }
    }
    return c;
  }
};

// The episode behind the determinism checks: stand under PD for 0.3 s, a 2 N s push, 0.5 s more of PD, then
// zero torque for 0.7 s (a fall with impacts on feet, links and torso). Returns the final state hash.
inline std::uint64_t runHashEpisode(Simulator& sim) {
  sim.reset(StandingPose{});
  StanceController ctrl(sim.robot(), sim.groundTruth().q);
  sim.scheduleImpulse({Eigen::Vector2d(2.0, 0.0), ImpulseTrigger::AtTime, 0.3, 0});
  for (int k = 0; k < 1500; ++k) {
    model::ActuatorCommand c = ctrl.command(sim.sensors());
    if (k >= 800) c.tau.setZero();
    sim.setCommand(c);
    sim.step();
  }
  return sim.stateHash();
}

}  // namespace mft::sim::test
