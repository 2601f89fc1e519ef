#pragma once
// One run of the offline pipeline: grid both spaces, fit the joint-space polygon, measure it, and assemble
// the polytope that config/mft_space.yaml stores. Shared by `fit`, `figure` and `all`.
#include <string>

#include "cli_args.hpp"
#include "model/mft_grid.hpp"
#include "model/mft_polygon_fit.hpp"
#include "model/mft_polytope.hpp"
#include "progress.hpp"

namespace mft::tools {

struct SpaceSettings {
  double joint_step_rad = 0.01;
  double cartesian_step_m = 0.01;
  int edges = model::kMftLegEdges;
  int starts = 24;
  unsigned rng_seed = 1;
  model::MftCriteria criteria;
};

// Options shared by every command that grids: thresholds, RACI form, resolutions, fit settings.
extern const char* const kSpaceOptions[];
SpaceSettings settingsFromArgs(const CliArgs& a, const model::RobotDescription& robot);
// The criteria part only (for `index`).
model::MftCriteria criteriaFromArgs(const CliArgs& a, const model::RobotDescription& robot);

struct SpaceResult {
  model::LabelGrid joint, cartesian;
  model::PolygonFitResult fit;
  model::PolygonQuality quality;
  model::MftPolytope polytope;  // A, b only when the polygon is a hexagon (has_augmented)
  bool has_augmented = false;
  double grid_seconds = 0.0, fit_seconds = 0.0;
};

// Throws std::runtime_error when the fit finds no polygon.
SpaceResult runSpace(const model::RobotDescription& robot, const SpaceSettings& s, Progress& progress);

// Grids only (for `figure` with a stored polytope).
void gridSpaces(const model::RobotDescription& robot, const model::MftCriteria& c, double joint_step, double cart_step,
                Progress& progress, model::LabelGrid* joint, model::LabelGrid* cartesian);

// Writes the YAML; throws std::runtime_error if the file cannot be written.
void writePolytopeFile(const std::string& path, const SpaceResult& r, const model::RobotDescription& robot);

std::string summaryJson(const SpaceResult& r);
std::string summaryText(const SpaceResult& r);

}  // namespace mft::tools
