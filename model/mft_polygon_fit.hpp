#pragma once
// Conservative convex polygon fit of a gridded preferable set (docs/reference/five-bar-theory.md#the-polygon-fit; the paper's conditions 1
// and 2). Cells are axis-aligned boxes around grid nodes. A bad cell is excluded by edge k when its whole box
// lies beyond that edge; the polygon is feasible when every bad cell is excluded by some edge, so it never
// touches a bad cell. Greedy shrink from a seed, exact offset ascent, angle pattern search and vertex cuts,
// from several random starts (deterministic RNG seed); the largest area wins.
#include <functional>
#include <string>
#include <vector>

#include "model/mft_grid.hpp"
#include "model/mft_polygon.hpp"

namespace mft::model {

struct FitCells {
  std::vector<Eigen::Vector2d> good;  // centres of preferable cells
  std::vector<Eigen::Vector2d> bad;   // centres of the bad cells that matter (see fitCellsFromGrid)
  Eigen::Vector2d half{0, 0};         // half widths of a cell box
};

// Preferable nodes are good. Only bad cells that share a point with a good cell are kept (a convex polygon
// around a good seed that misses all of them misses every bad cell), with the grid framed by a ring of bad
// cells so the polygon stays bounded.
FitCells fitCellsFromGrid(const LabelGrid& g);

struct PolygonFitOptions {
  int edges = 6;
  int starts = 24;
  unsigned rng_seed = 1;
  double margin = 1e-6;         // extra clearance between an edge and an excluded cell box
  bool has_seed_point = false;  // where the polygon must stay; default: the good cell nearest the good centroid
  Eigen::Vector2d seed_point{0, 0};
  double delta_start = 0.2, delta_min = 1e-3;  // angle pattern search steps [rad]
  std::function<void(int, int)> progress;       // (starts done, starts total)
};

struct PolygonFitResult {
  bool ok = false;
  std::string error;
  HalfPlanePolygon polygon;  // edges sorted by normal angle, redundant offsets tightened
  double area = 0.0;
  Eigen::Vector2d seed{0, 0};  // the good node the polygon was grown around
  int best_start = -1;
};

PolygonFitResult fitConservativePolygon(const FitCells& cells, const PolygonFitOptions& options);

// Condition 1 and 2 figures on the grid: nodes inside the polygon, coverage of good nodes, and r_max, the
// largest distance from a good node left outside to the polygon.
struct PolygonQuality {
  int good_total = 0, good_inside = 0, bad_inside = 0, unreachable_inside = 0;
  double coverage = 0.0;
  double r_max = 0.0;
};
PolygonQuality assessPolygon(const LabelGrid& g, const HalfPlanePolygon& p);

}  // namespace mft::model
