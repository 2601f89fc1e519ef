#include "model/mft_indices.hpp"

#include <algorithm>
#include <cmath>

namespace mft::model {

namespace {
// A planar direction turned by +90 degrees: the velocity direction of a point on a link of direction e that
// turns about the link's other end.
Eigen::Vector2d perpendicular(const Eigen::Vector2d& e) { return {-e.y(), e.x()}; }
}  // namespace

double transmissionAngleSine(const Eigen::Vector2d& f, const Eigen::Vector2d& v) {
  const double scale = f.norm() * v.norm();
  if (!(scale > 0.0)) return 0.0;
  return std::min(1.0, std::abs(f.dot(v)) / scale);
}

PlanarTwist PlanarTwist::rotationAbout(const Eigen::Vector2d& c, double rate) {
  // A point X moves with rate * perp(X - c); at the origin X = 0.
  return {rate, rate * perpendicular(-c)};
}

PlanarWrench PlanarWrench::forceThrough(const Eigen::Vector2d& point, const Eigen::Vector2d& force) {
  return {force, cross2(point, force)};
}

double reciprocalProduct(const PlanarWrench& W, const PlanarTwist& T) { return W.f.dot(T.v) + W.m * T.w; }

LimbPowers limbPowers(const PlanarWrench& transmission, const PlanarTwist& input, const PlanarTwist& output) {
  return {std::abs(reciprocalProduct(transmission, input)), std::abs(reciprocalProduct(transmission, output))};
}

TransmissionIndices transmissionIndices(const FiveBarPose& p) {
  const Eigen::Vector2d e_r = linkDirection(p.q_rear), e_f = linkDirection(p.q_fore);
  const Eigen::Vector2d u_r = linkDirection(p.shank_rear), u_f = linkDirection(p.shank_fore);
  TransmissionIndices t;
  t.iti_rear = transmissionAngleSine(u_r, perpendicular(e_r));
  t.iti_fore = transmissionAngleSine(u_f, perpendicular(e_f));
  t.oti = transmissionAngleSine(u_r, perpendicular(u_f));
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
