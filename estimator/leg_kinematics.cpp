#include "estimator/leg_kinematics.hpp"

#include <cmath>

namespace mft::estimator {

LegJoints legJoints(const model::SensorReadings& s, int leg) {
  const int rear = 2 * leg, fore = 2 * leg + 1;
  LegJoints j;
  j.pos = {s.actuated_pos[rear], s.passive_pos[rear], s.actuated_pos[fore], s.passive_pos[fore]};
  j.vel = {s.actuated_vel[rear], s.passive_vel[rear], s.actuated_vel[fore], s.passive_vel[fore]};
  return j;
}

FootInBase footInBase(const model::FiveBarGeometry& g, const LegJoints& j) {
  // A link at absolute angle a points along (sin a, -cos a); its rate of direction is (cos a, sin a).
  auto tangent = [](double a) { return Eigen::Vector2d(std::cos(a), std::sin(a)); };
  FootInBase out;
  const Eigen::Vector2d hips[2] = {g.hipRear(), g.hipFore()};
  for (int chain = 0; chain < 2; ++chain) {
    const double q = j.pos[2 * chain], knee = j.pos[2 * chain + 1];
    const double qd = j.vel[2 * chain], kneed = j.vel[2 * chain + 1];
    out.pos += 0.5 * (hips[chain] + g.l1 * model::linkDirection(q) + g.l2 * model::linkDirection(q + knee));
    out.vel += 0.5 * (g.l1 * qd * tangent(q) + g.l2 * (qd + kneed) * tangent(q + knee));
  }
  return out;
}

}  // namespace mft::estimator
