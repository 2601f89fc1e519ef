#pragma once
// Gridded reachable and preferable space of one leg, in actuated joint space (q_rear, q_fore) over the hip
// limit box, and in Cartesian foot space (x, z) in the leg frame. Grid nodes sit at lo + i * step.
#include <cstdint>
#include <functional>
#include <vector>

#include "model/mft_criteria.hpp"

namespace mft::model {

enum CellLabel : std::uint8_t { kCellUnreachable = 0, kCellReachable = 1, kCellPreferable = 2 };

struct GridAxis {
  double lo = 0.0;
  double step = 0.0;
  int n = 0;
  double at(int i) const { return lo + i * step; }
};

struct LabelGrid {
  GridAxis x, y;  // joint space: x = q_rear, y = q_fore; Cartesian: x forward, y = z up
  std::vector<std::uint8_t> labels;  // row-major, index j * x.n + i
  std::uint8_t at(int i, int j) const { return labels[static_cast<std::size_t>(j) * x.n + i]; }
  Eigen::Vector2d node(int i, int j) const { return {x.at(i), y.at(j)}; }
  int count(std::uint8_t label) const;
  int countAtLeast(std::uint8_t label) const;  // reachable = countAtLeast(kCellReachable)
};

// Called with (rows done, rows total); may be empty.
using GridProgress = std::function<void(int, int)>;

// Nodes lo, lo + step, ... up to hi (inclusive within 1e-9 step) on each hip axis.
LabelGrid gridJointSpace(const MftLegModel& m, const MftCriteria& c, double step_rad, const GridProgress& progress = {});
// A square around the hips covering the whole reach, nodes on multiples of step (the hip axis is a node).
LabelGrid gridCartesianSpace(const MftLegModel& m, const MftCriteria& c, double step_m, const GridProgress& progress = {});

}  // namespace mft::model
