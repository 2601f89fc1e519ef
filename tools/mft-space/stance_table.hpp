#pragma once
// LTI and RACI along the vertical stance (foot straight below the hip, d = z_B - foot radius) and whether the
// configuration lies inside the fitted polygon.
#include <string>
#include <vector>

#include "model/mft_criteria.hpp"
#include "model/mft_polytope.hpp"

namespace mft::tools {

struct StanceRow {
  double base_height = 0.0, d = 0.0;
  model::LegEvaluation eval;
  double raci_optimal = 0.0, raci_fixed = 0.0;
  bool inside = false;
};

std::vector<StanceRow> stanceTable(const model::RobotDescription& robot, const model::MftCriteria& c,
                                   const model::MftLegPolygon& polygon, double from, double to, double step);
std::string stanceText(const std::vector<StanceRow>& rows, const model::MftCriteria& c);
std::string stanceJson(const std::vector<StanceRow>& rows);

// One configuration (`index`).
std::string indexText(const model::LegEvaluation& e, const model::MftCriteria& c);
std::string indexJson(const model::LegEvaluation& e, const model::MftCriteria& c);

}  // namespace mft::tools
