#pragma once
// The offline MFT preferable space of one leg, end to end (paper sec. III-B): grid the actuated joint space and
// the Cartesian foot space, fit the conservative polygon, measure it, and assemble the polytope that
// config/mft_space.yaml stores. mft-space's `fit`, `figure` and `all` run it; a library user fits its own robot.
#include <functional>
#include <string>

#include "model/mft_grid.hpp"
#include "model/mft_polygon_fit.hpp"
#include "model/mft_polytope.hpp"

namespace mft::model {

struct MftSpaceSettings : MftFitSettings {
  MftCriteria criteria;
};

// Where a fit reports its stages (one line each) and its long loops (what, done, total); either may be empty.
struct MftSpaceProgress {
  std::function<void(const std::string& what)> stage;
  std::function<void(const std::string& what, int done, int total)> percent;
};

struct MftSpaceResult {
  LabelGrid joint, cartesian;
  PolygonFitResult fit;
  PolygonQuality quality;
  MftPolytope polytope;  // A, b only when the polygon is a hexagon (has_augmented)
  bool has_augmented = false;
  double grid_seconds = 0.0, fit_seconds = 0.0;
};

// Throws std::runtime_error when the fit finds no polygon.
MftSpaceResult fitMftSpace(const RobotDescription& robot, const MftSpaceSettings& s,
                           const MftSpaceProgress& progress = {});

// The two grids only (a figure of a stored polytope).
void gridMftSpaces(const RobotDescription& robot, const MftCriteria& c, double joint_step, double cart_step,
                   const MftSpaceProgress& progress, LabelGrid* joint, LabelGrid* cartesian);

}  // namespace mft::model
