#pragma once
// LTI of one leg from its generalized coordinates (docs/five-bar-theory.md#transmission-indices-lti). Local copy until model/ provides
// the MFT indices: LTI = min(|sin knee_rear|, |sin knee_fore|, |sin(shank_fore - shank_rear)|).
#include <algorithm>
#include <cmath>

#include "model/coordinates.hpp"

namespace mft::sim {

inline double legTransmissionIndex(const model::VectorQ& q, int leg) {
  const double hr = q[model::hipRearIndex(leg)], kr = q[model::kneeRearIndex(leg)];
  const double hf = q[model::hipForeIndex(leg)], kf = q[model::kneeForeIndex(leg)];
  return std::min({std::abs(std::sin(kr)), std::abs(std::sin(kf)), std::abs(std::sin((hf + kf) - (hr + kr)))});
}

}  // namespace mft::sim
