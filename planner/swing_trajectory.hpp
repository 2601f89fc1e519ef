#pragma once
// Swing-foot trajectory (paper: cubic from lift-off to the pre-impact target). x: one cubic with zero end
// velocities. z: a cubic up to the apex at mid-swing, a cubic down to the ground height that arrives with a
// small downward speed; past the nominal duration (late touchdown) the foot keeps descending at that speed.
#include <Eigen/Core>

namespace mft::planner {

struct PosVelAcc {
  double pos = 0.0, vel = 0.0, acc = 0.0;
};

// Cubic Hermite segment from (p0, v0) to (p1, v1) over duration T, evaluated at t in [0, T] (clamped).
PosVelAcc cubicHermite(double p0, double v0, double p1, double v1, double T, double t);

struct SwingSpec {
  Eigen::Vector2d liftoff{0, 0};    // world [x, z] at lift-off
  double target_x = 0.0;            // pre-impact x (19)
  double ground_z = 0.0;            // height to land at
  double duration_s = 0.35;         // nominal swing duration
  double lift_height_m = 0.06;      // apex = max(liftoff z, ground_z) + lift height
  double touchdown_speed_mps = 0.0; // downward speed at t = duration and after it
};

struct SwingSample {
  Eigen::Vector2d pos{0, 0}, vel{0, 0}, acc{0, 0};
};

// t = time since lift-off; t < 0 is clamped to 0, t > duration continues the late-touchdown descent.
SwingSample evaluateSwing(const SwingSpec& spec, double t);

}  // namespace mft::planner
