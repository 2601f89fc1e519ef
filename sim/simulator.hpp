#pragma once
// The ODE simulator of the planar five-bar biped (issue 4). Built from the robot description alone:
// a torso held in the sagittal plane (Plane2D in a Y-up ODE world: the paper's boom), two five-bar legs
// (hips, knees, a ball or hinge closing each loop at the ankle), point feet with Coulomb friction, series
// elastic actuators, hard stops, sensors with optional seeded noise, terrain and pushes. dWorldStep only:
// the same inputs give bit-identical trajectories. No ODE type appears in this header.
//
// Foot contact: the model's foot point is the ankle (foot_radius_m = 0). ODE collides a sphere of
// SimOptions::foot_collision_radius_m centred on the ankle against terrain solids that are lowered by that
// radius (by radius / cos(angle) on slopes), and applies every foot contact force at the ankle. So the ankle
// rests on the nominal terrain height (minus the contact spring's sink, F/k) and friction makes no moment
// about it, exactly like the model's point foot. On rough ground the rounding of the sphere lifts the ankle
// by at most radius * (1/cos(bump slope) - 1) (0.4 mm for 2 cm bumps every 5 cm and a 5 mm sphere).
//
// Threading: one thread owns a Simulator (ODE worlds are not shared); any thread may own one.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "model/coordinates.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"
#include "sim/sim_options.hpp"
#include "sim/terrain.hpp"

namespace mft::sim {

// A standing start. The base frame (hip axis) is placed base_height_m above the terrain at base_x_m; each foot
// at its x offset (world, from the base) on the terrain; the legs follow by five-bar inverse kinematics.
struct StandingPose {
  double base_x_m = 0.0;
  double base_height_m = 0.40;
  double pitch_rad = 0.0;
  std::array<double, model::kNumLegs> foot_offset_x_m{0.0, 0.0};  // [right, left]
  // > 0: start in the air, each foot this far below the hip axis (base frame) instead of on the ground.
  double leg_length_m = 0.0;
  // true: each foot starts sunk by its static contact deflection (half the weight on each foot) and the SEAs
  // start at the torque that holds half the weight on each foot (-J' f, leg masses ignored): no drop, no sag.
  bool settle = true;
};

enum class ImpulseTrigger { AtTime, AtLiftOff };

// A sagittal push on the torso CoM, applied as force J/h during exactly one physics step.
struct ImpulseSpec {
  Eigen::Vector2d impulse_Ns{0.0, 0.0};  // world [x, z]
  ImpulseTrigger trigger = ImpulseTrigger::AtTime;
  double time_s = 0.0;  // AtTime: the first physics step that starts at or after this time
  int leg = 0;          // AtLiftOff: the physics step after the next lift-off of this leg (0 right, 1 left)
  std::uint64_t id = 0;  // the caller's tag, carried into AppliedImpulse (which request was applied when)
};

struct AppliedImpulse {
  Eigen::Vector2d impulse_Ns{0.0, 0.0};
  double time_s = 0.0;  // start of the physics step that carried it
  std::uint64_t id = 0;  // ImpulseSpec::id
};

// The first contact of a non-foot body with the terrain since reset: which body, when and where. A diagnosis of
// falls by body contact (e.g. a shank on an obstacle's edge), not used by the simulation itself.
struct BodyContact {
  bool seen = false;
  double time_s = 0.0;  // start of the physics step
  int body = -1;        // robotBodyName(body): torso, then per leg (right, left) and side (rear, fore) thigh, shank
  Eigen::Vector2d point{0.0, 0.0};   // contact point, world [x, z]
  Eigen::Vector2d normal{0.0, 0.0};  // contact normal, world [x, z], pointing into the robot's body
  double depth_m = 0.0;              // penetration
};
// "torso", "right rear thigh", "right rear shank", "right fore thigh", ..., "left fore shank"; "none" otherwise.
const char* robotBodyName(int body);

struct SimStats {
  std::uint64_t control_steps = 0;
  std::uint64_t physics_steps = 0;
  double closure_error_m = 0.0;      // ankle anchor mismatch now (max over legs)
  double max_closure_error_m = 0.0;  // since reset
  std::array<std::uint64_t, model::kNumLegs> touchdowns{};
  std::array<std::uint64_t, model::kNumLegs> liftoffs{};
  std::array<double, model::kNumLegs> last_liftoff_time_s{-1.0, -1.0};
  std::uint64_t body_contact_steps = 0;  // physics steps in which a thigh, shank or the torso touched the ground
  BodyContact first_body_contact;        // the first of those contacts
  std::uint64_t ode_messages = 0;        // ODE warnings (e.g. LCP internal errors) since reset
  std::vector<AppliedImpulse> impulses;  // applied so far
};

class Simulator {
 public:
  // Throws std::runtime_error if libode is not double precision, config::ConfigError / std::invalid_argument
  // on inconsistent inputs. The robot starts standing at 0.40 m (reset(StandingPose{})).
  Simulator(const model::RobotDescription& robot, const SimOptions& options, const Terrain& terrain);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Rebuilds the robot standing (time and tick back to 0, noise reseeded, pending impulses dropped).
  void reset(const StandingPose& pose);
  // Rebuilds the robot at any state whose loops are closed (q, qd in the model's coordinates; throws
  // std::invalid_argument otherwise), with the SEAs at rest at sea_torque. Time and tick back to 0.
  void setState(const model::VectorQ& q, const model::VectorQ& qd,
                const model::VectorA& sea_torque = model::VectorA::Zero());

  // The command is held over the next control period(s).
  void setCommand(const model::ActuatorCommand& command);
  // One control period: SimOptions::substeps physics steps.
  void step();

  const model::SensorReadings& sensors() const { return sensors_; }
  const model::GroundTruthState& groundTruth() const { return truth_; }
  const SimStats& stats() const { return stats_; }
  void scheduleImpulse(const ImpulseSpec& impulse);

  std::uint64_t tick() const { return tick_; }
  double time() const { return time_; }
  double physicsStep() const { return h_; }
  const model::RobotDescription& robot() const { return robot_; }
  const SimOptions& options() const { return options_; }
  const Terrain& terrain() const { return terrain_; }

  // Diagnostics for tests and tools.
  std::uint64_t stateHash() const;                // FNV-1a over every body state, SEA state and clock
  double mechanicalEnergy() const;                // kinetic + gravitational of all bodies [J]
  Eigen::Vector2d linearMomentum() const;         // world [x, z], all bodies
  Eigen::Vector2d anklePosition(int leg) const;   // world [x, z] of the ankle (model foot point)
  model::VectorA seaTorque() const;               // clean SEA output torques acting on the hips
  // The drive (output side) over the last physics step: sea_motor: the motor torque (mean over the torque loop's
  // periods) and the rotor speed; sea, ideal: the limited torque fed to the SEA and the hip rate.
  model::VectorA motorTorque() const;
  model::VectorA motorSpeed() const;
  // The configuration reset(pose) builds: q and the SEA torques it starts with. Throws if a foot is out of reach.
  struct StandingConfiguration {
    model::VectorQ q = model::VectorQ::Zero();
    model::VectorA holding_torque = model::VectorA::Zero();
  };
  StandingConfiguration standingConfiguration(const StandingPose& pose) const;
  // The highest collision surface below (x, z_from) by ray cast (NaN if none): the lowered solid, see above.
  double rayTerrain(double x, double z_from = 10.0) const;
  // The ankle height at which the foot sphere sinks `depth` into the terrain at x (by bisection on contacts).
  double footRestHeight(double x, double depth = 0.0) const;

 private:
  struct Impl;
  void rebuild(const model::VectorQ& q, const model::VectorQ& qd, const model::VectorA& sea_torque);
  void physicsStep(int substep);
  void refreshOutputs(const Eigen::Vector2d& imu_vel_before);
  Eigen::Vector2d imuVelocity() const;  // world velocity of the IMU point

  model::RobotDescription robot_;
  SimOptions options_;
  Terrain terrain_;
  double h_ = 0.001;
  std::unique_ptr<Impl> impl_;
  model::ActuatorCommand command_;
  std::uint64_t tick_ = 0;
  double time_ = 0.0;
  model::SensorReadings sensors_;
  model::GroundTruthState truth_;
  SimStats stats_;
};

}  // namespace mft::sim
