#include "planner/swing_trajectory.hpp"

#include <algorithm>

namespace mft::planner {

PosVelAcc cubicHermite(double p0, double v0, double p1, double v1, double T, double t) {
  t = std::clamp(t, 0.0, T);
  // p(t) = p0 + v0 t + c2 t^2 + c3 t^3 with p(T) = p1, p'(T) = v1.
  const double d = p1 - p0;
  const double c2 = (3.0 * d - (2.0 * v0 + v1) * T) / (T * T);
  const double c3 = (-2.0 * d + (v0 + v1) * T) / (T * T * T);
  return {p0 + t * (v0 + t * (c2 + t * c3)), v0 + t * (2.0 * c2 + 3.0 * c3 * t), 2.0 * c2 + 6.0 * c3 * t};
}

SwingSample evaluateSwing(const SwingSpec& s, double t) {
  const double T = s.duration_s;
  t = std::max(t, 0.0);
  SwingSample out;

  // Past T the foot holds the target x (the cubic's end acceleration is not continued).
  const PosVelAcc x = t <= T ? cubicHermite(s.liftoff.x(), 0.0, s.target_x, 0.0, T, t) : PosVelAcc{s.target_x, 0.0, 0.0};
  out.pos.x() = x.pos;
  out.vel.x() = x.vel;
  out.acc.x() = x.acc;

  const double apex = std::max(s.liftoff.y(), s.ground_z) + s.lift_height_m;
  PosVelAcc z;
  if (t < 0.5 * T) {
    z = cubicHermite(s.liftoff.y(), 0.0, apex, 0.0, 0.5 * T, t);
  } else if (t <= T) {
    z = cubicHermite(apex, 0.0, s.ground_z, -s.touchdown_speed_mps, 0.5 * T, t - 0.5 * T);
  } else {
    // Late touchdown: keep descending at the touchdown speed until contact (the schedule bounds this).
    z = {s.ground_z - s.touchdown_speed_mps * (t - T), -s.touchdown_speed_mps, 0.0};
  }
  out.pos.y() = z.pos;
  out.vel.y() = z.vel;
  out.acc.y() = z.acc;
  return out;
}

}  // namespace mft::planner
