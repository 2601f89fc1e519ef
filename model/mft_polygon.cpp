#include "model/mft_polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mft::model {

Eigen::Vector2d HalfPlanePolygon::normal(int k) const { return {std::cos(angle[k]), std::sin(angle[k])}; }

bool HalfPlanePolygon::contains(const Eigen::Vector2d& x, double tol) const {
  for (int k = 0; k < size(); ++k)
    if (normal(k).dot(x) > offset[k] + tol) return false;
  return true;
}

std::vector<Eigen::Vector2d> clipHalfPlane(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& n, double b) {
  std::vector<Eigen::Vector2d> out;
  const std::size_t m = poly.size();
  out.reserve(m + 1);
  for (std::size_t i = 0; i < m; ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % m];
    const double sp = n.dot(p) - b, sq = n.dot(q) - b;
    if (sp <= 0.0) out.push_back(p);
    if ((sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0)) out.push_back(p + (sp / (sp - sq)) * (q - p));
  }
  return out;
}

std::vector<Eigen::Vector2d> HalfPlanePolygon::vertices() const {
  std::vector<Eigen::Vector2d> v = {box_lo, {box_hi.x(), box_lo.y()}, box_hi, {box_lo.x(), box_hi.y()}};
  for (int k = 0; k < size() && !v.empty(); ++k) v = clipHalfPlane(v, normal(k), offset[k]);
  return v;
}

double polygonArea(const std::vector<Eigen::Vector2d>& v) {
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d& p = v[i];
    const Eigen::Vector2d& q = v[(i + 1) % v.size()];
    a += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * std::abs(a);
}

double HalfPlanePolygon::area() const { return polygonArea(vertices()); }

double pointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

double HalfPlanePolygon::distanceOutside(const Eigen::Vector2d& x) const {
  if (contains(x)) return 0.0;
  const auto v = vertices();
  if (v.empty()) return std::numeric_limits<double>::infinity();
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < v.size(); ++i) d = std::min(d, pointSegmentDistance(x, v[i], v[(i + 1) % v.size()]));
  return d;
}

void HalfPlanePolygon::tightenRedundant() {
  const auto v = vertices();
  if (v.empty()) return;
  for (int k = 0; k < size(); ++k) {
    const Eigen::Vector2d n = normal(k);
    double support = -std::numeric_limits<double>::infinity();
    for (const auto& p : v) support = std::max(support, n.dot(p));
    offset[k] = std::min(offset[k], support);
  }
}

}  // namespace mft::model
