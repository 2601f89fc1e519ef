#pragma once
// Paper (18): the planner's base references, z_ref = z_cmd and theta_ref = 0 (x is left passive while stepping).
// Not in the paper: z_ref moves toward z_cmd at no more than max_rate, since a step in the command would
// otherwise be a step in the reference.
#include <Eigen/Core>

namespace mft::planner {

struct HeightPitchReference {
  Eigen::Vector3d base_z{0, 0, 0};      // [pos, vel, acc] of the base height
  Eigen::Vector3d base_pitch{0, 0, 0};  // [pos, vel, acc] of the pitch: always 0
};

// One tick of dt from the last height reference z_ref toward z_cmd. max_rate >= 0 [m/s], dt >= 0 [s]; the velocity
// is the step taken over dt (0 when dt = 0), the acceleration 0.
HeightPitchReference heightPitchReference(double z_ref, double z_cmd, double max_rate, double dt);

}  // namespace mft::planner
