#pragma once
// LTI of a leg straight from the generalized coordinates (docs/five-bar-theory.md#transmission-indices-lti):
// min(|sin knee_rear|, |sin knee_fore|, |sin(shank_fore - shank_rear)|), shank = hip + knee (absolute).
#include <algorithm>
#include <cmath>

#include "model/coordinates.hpp"

namespace mft::wbc {

inline double legLti(const model::VectorQ& q, int leg) {
  const double knee_r = q[model::kneeRearIndex(leg)];
  const double knee_f = q[model::kneeForeIndex(leg)];
  const double shank_r = q[model::hipRearIndex(leg)] + knee_r;
  const double shank_f = q[model::hipForeIndex(leg)] + knee_f;
  return std::min({std::abs(std::sin(knee_r)), std::abs(std::sin(knee_f)), std::abs(std::sin(shank_f - shank_r))});
}

}  // namespace mft::wbc
