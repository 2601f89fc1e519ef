#pragma once
// The paper's Fig. 5: writes the grids and the polygon to a JSON data file and runs mft_space_figure.py
// (/usr/bin/python3 + matplotlib) on it.
#include <string>

#include "model/mft_grid.hpp"
#include "model/mft_polytope.hpp"

namespace mft::tools {

struct FigureInput {
  const model::LabelGrid* joint = nullptr;
  const model::LabelGrid* cartesian = nullptr;
  const model::MftLegPolygon* polygon = nullptr;
  const model::MftCriteria* criteria = nullptr;
  const model::RobotDescription* robot = nullptr;
  double coverage = 0.0, r_max = 0.0, area = 0.0;
};

void writeFigureData(const std::string& path, const FigureInput& in);

// Runs the script; returns "" on success, else why the figure was not drawn (e.g. matplotlib missing).
std::string drawFigure(const std::string& data_path, const std::string& png_path, const std::string& script);

}  // namespace mft::tools
