#pragma once
// Internal: the robot's ODE bodies, joints and geoms, built from a closed-loop state in the model's
// generalized coordinates, and read back into them. Frame mapping (docs/reference/simulation.md#frames): project (x, y, z) -> ODE
// (x, z, -y), a Y-up world, so a model angle (CCW about -y) is an ODE angle about +z, unchanged.
#include <ode/ode.h>

#include <Eigen/Core>
#include <array>
#include <vector>

#include "model/coordinates.hpp"
#include "model/robot_description.hpp"
#include "sim/sim_options.hpp"

namespace mft::sim {

// A hinge read as an unwrapped model coordinate: q = centre + unwrapped ODE angle, with centre = the joint's
// coordinate when the robot was built (ODE's zero). Every stop range is narrower than pi, so the stops (which
// ODE allows only within (-pi, pi)) never straddle ODE's wrap point.
struct HingeEncoder {
  dJointID joint = nullptr;
  double centre = 0.0;
  double unwrapped = 0.0;  // accumulated ODE angle
  double last_raw = 0.0;
  double position() const { return centre + unwrapped; }
  void update();
};

struct OdeRobot {
  dBodyID torso = nullptr;
  dBodyID thigh[model::kNumLegs][2]{};  // [leg][0 rear, 1 fore]
  dBodyID shank[model::kNumLegs][2]{};
  dJointID closure[model::kNumLegs]{};
  dJointID plane = nullptr;
  dGeomID foot[model::kNumLegs]{};     // sphere centred on the ankle, carried by the rear shank
  std::vector<dGeomID> body_geoms;     // link capsules and the torso box (falls)
  std::array<HingeEncoder, 8> joints;  // in q order: q4 .. q11
  double pitch_unwrapped = 0.0, pitch_last_raw = 0.0;
  std::array<dBodyID, 9> bodies() const {
    return {torso, thigh[0][0], shank[0][0], thigh[0][1], shank[0][1], thigh[1][0], shank[1][0], thigh[1][1], shank[1][1]};
  }
  dJointID hip(int leg, int chain) const { return joints[static_cast<std::size_t>(4 * leg + 2 * chain)].joint; }
};

struct RobotBuildParams {
  double foot_radius = 0.005;
  double stop_erp = 0.2, stop_cfm = 1e-5;
};

// Creates bodies, joints and geoms in `world` at (q, qd). Throws std::invalid_argument if the loops are not
// closed (position error > 1e-6 m or velocity error > 1e-6 m/s) or a joint is outside its hard stops.
void buildRobot(dWorldID world, const model::RobotDescription& d, const SimOptions& o, const RobotBuildParams& p,
                const model::VectorQ& q, const model::VectorQ& qd, OdeRobot* robot);
void destroyRobotGeoms(OdeRobot* robot);

// After each physics step: unwrap encoders and pitch, re-project the torso into the plane (docs/reference/simulation.md#frames).
void updateRobotAfterStep(OdeRobot* robot, bool fixed_torso);

// Generalized coordinates and velocities of the current ODE state.
void readRobotState(const OdeRobot& robot, const model::RobotDescription& d, model::VectorQ* q, model::VectorQ* qd);

// Ankle mismatch between the two shanks of a leg [m].
double closureError(const OdeRobot& robot, int leg, const SimOptions& o);
Eigen::Vector2d ankle(const OdeRobot& robot, int leg, const SimOptions& o);

}  // namespace mft::sim
