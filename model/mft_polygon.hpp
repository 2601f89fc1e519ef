#pragma once
// A convex polygon as the intersection of half-planes n_k' x <= b_k with unit normals n_k = (cos t_k, sin t_k).
// Vertices come from clipping a bounding box, so redundant or very loose edges are harmless.
#include <Eigen/Core>
#include <vector>

namespace mft::model {

struct HalfPlanePolygon {
  std::vector<double> angle;   // t_k
  std::vector<double> offset;  // b_k
  Eigen::Vector2d box_lo{-1e3, -1e3}, box_hi{1e3, 1e3};  // clip box for vertices (keeps P bounded)

  int size() const { return static_cast<int>(angle.size()); }
  Eigen::Vector2d normal(int k) const;
  bool contains(const Eigen::Vector2d& x, double tol = 0.0) const;
  // Counter-clockwise vertices of the clipped polygon (empty when the polygon is empty).
  std::vector<Eigen::Vector2d> vertices() const;
  double area() const;
  // Distance from x to the polygon (0 inside).
  double distanceOutside(const Eigen::Vector2d& x) const;
  // Sets every edge that touches no polygon side of positive length to the support value max_v n_k' v, so a
  // redundant row is finite and tight at a vertex.
  void tightenRedundant();
};

double polygonArea(const std::vector<Eigen::Vector2d>& v);
std::vector<Eigen::Vector2d> clipHalfPlane(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& n, double b);
double pointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

}  // namespace mft::model
