#include "model/mft_indices.hpp"

#include <algorithm>
#include <cmath>

namespace mft::model {

namespace {
// |sin| of the angle between two unit vectors, clamped so rounding never leaves [0, 1].
double sinBetween(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return std::min(1.0, std::abs(cross2(a, b))); }
}  // namespace

TransmissionIndices transmissionIndices(const FiveBarPose& p) {
  const Eigen::Vector2d e_r = linkDirection(p.q_rear), e_f = linkDirection(p.q_fore);
  const Eigen::Vector2d u_r = linkDirection(p.shank_rear), u_f = linkDirection(p.shank_fore);
  TransmissionIndices t;
  t.iti_rear = sinBetween(e_r, u_r);
  t.iti_fore = sinBetween(e_f, u_f);
  t.oti = sinBetween(u_r, u_f);
  return t;
}

FiveBarStatus transmissionIndicesAt(const FiveBarGeometry& g, double q_rear, double q_fore, TransmissionIndices* out) {
  *out = TransmissionIndices{};
  if (!std::isfinite(q_rear) || !std::isfinite(q_fore)) return FiveBarStatus::Unreachable;
  FiveBarPose p;
  const FiveBarStatus s = fiveBarForward(g, q_rear, q_fore, &p);
  if (s == FiveBarStatus::Ok) *out = transmissionIndices(p);
  // Degenerate: both shanks hang from the same knee and may take any common direction; the output twist
  // of either chain is a free rotation about that knee, so the OTI (and hence the LTI) is 0.
  return s;
}

double legTransmissionIndex(const VectorQ& q, int leg) {
  const double knee_r = q[kneeRearIndex(leg)];
  const double knee_f = q[kneeForeIndex(leg)];
  const double shank_r = q[hipRearIndex(leg)] + knee_r;
  const double shank_f = q[hipForeIndex(leg)] + knee_f;
  return std::min({std::abs(std::sin(knee_r)), std::abs(std::sin(knee_f)), std::abs(std::sin(shank_f - shank_r))});
}

}  // namespace mft::model
