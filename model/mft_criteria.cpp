#include "model/mft_criteria.hpp"

#include <cmath>
#include <limits>

#include "common/enum_names.hpp"

namespace mft::model {

MftLegModel MftLegModel::from(const RobotDescription& d) {
  MftLegModel m;
  m.geometry = FiveBarGeometry::from(d);
  m.inertia = LegInertiaParams::from(d);
  m.rear_hip = d.rear_hip_rad;
  m.fore_hip = d.fore_hip_rad;
  m.rear_knee = d.rear_knee_rad;
  m.fore_knee = d.fore_knee_rad;
  m.foot_radius_m = d.foot_radius_m;
  m.knee_stop_margin_rad = d.knee_hard_stop_margin_rad;
  return m;
}

MftCriteria MftCriteria::defaults(const RobotDescription& d) {
  MftCriteria c;
  c.raci = {0.0, actuatorRaciLimit(d.actuator)};
  c.raci_options = RaciOptions::fromRobot(d);
  return c;
}

namespace {
LegEvaluation finish(const MftLegModel& m, const MftCriteria& c, FiveBarStatus s, const FiveBarPose& p) {
  LegEvaluation e;
  e.status = s;
  e.pose = p;
  e.raci.raci = e.raci.tau_rear = e.raci.tau_fore = std::numeric_limits<double>::infinity();
  if (s != FiveBarStatus::Ok) {
    e.raci.singular = s == FiveBarStatus::Degenerate;
    return e;
  }
  // Knees stop knee_stop_margin inside their (singular) limits. The thighs never cross (q_fore > q_rear): the
  // crossed branch of the loop is only reachable through the folded singularity, which the stops block.
  const double s_m = m.knee_stop_margin_rad;
  e.within_limits = m.rear_hip.contains(p.q_rear) && m.fore_hip.contains(p.q_fore) && p.q_fore > p.q_rear &&
                    p.knee_rear >= m.rear_knee.lo + s_m && p.knee_rear <= m.rear_knee.hi - s_m &&
                    p.knee_fore >= m.fore_knee.lo + s_m && p.knee_fore <= m.fore_knee.hi - s_m;
  e.reachable = e.within_limits;
  e.indices = transmissionIndices(p);
  e.raci = computeRaci(m.geometry, m.inertia, p, c.raci_options);
  e.preferable = e.reachable && c.lti.contains(e.indices.lti()) && std::isfinite(e.raci.raci) &&
                 c.raci.contains(e.raci.raci);
  return e;
}
}  // namespace

LegEvaluation evaluateLegAt(const MftLegModel& m, const MftCriteria& c, double q_rear, double q_fore) {
  FiveBarPose p;
  if (!std::isfinite(q_rear) || !std::isfinite(q_fore)) return finish(m, c, FiveBarStatus::Unreachable, p);
  const FiveBarStatus s = fiveBarForward(m.geometry, q_rear, q_fore, &p);
  return finish(m, c, s, p);
}

LegEvaluation evaluateLegAtFoot(const MftLegModel& m, const MftCriteria& c, const Eigen::Vector2d& foot) {
  FiveBarPose p;
  FiveBarStatus s = fiveBarInverse(m.geometry, foot, &p);
  // IK angles come from atan2 plus an opening and may leave (-pi, pi]; the limits are stated in that range.
  p.q_rear = wrapAngle(p.q_rear);
  p.q_fore = wrapAngle(p.q_fore);
  return finish(m, c, s, p);
}

LegEvaluation evaluateVerticalStance(const MftLegModel& m, const MftCriteria& c, double base_height_m) {
  return evaluateLegAtFoot(m, c, Eigen::Vector2d(0.0, -(base_height_m - m.foot_radius_m)));
}

Interval reachableBaseHeights(const MftLegModel& m, double foot_x_m, double step_m) {
  const MftCriteria criteria;  // the MFT thresholds play no part in `reachable`
  Interval out{1.0, 0.0};      // empty
  const double top = m.geometry.l1 + m.geometry.l2 + m.foot_radius_m;
  for (int k = 1; k * step_m <= top + 1e-12; ++k) {
    const double h = k * step_m;
    if (!evaluateLegAtFoot(m, criteria, Eigen::Vector2d(foot_x_m, -(h - m.foot_radius_m))).reachable) continue;
    if (out.lo > out.hi) out = {h, h};
    else out.hi = h;
  }
  return out;
}

constexpr config::EnumName<FiveBarStatus> kFiveBarStatusNames[] = {{FiveBarStatus::Ok, "ok"},
                                                                   {FiveBarStatus::Unreachable, "unreachable"},
                                                                   {FiveBarStatus::Degenerate, "degenerate"}};

const char* fiveBarStatusName(FiveBarStatus s) { return config::nameOf(kFiveBarStatusNames, s); }

}  // namespace mft::model
