#include "planner/foot_placement.hpp"

#include <algorithm>
#include <cmath>

namespace mft::planner {

double lipLambda(double gravity, double com_height) { return std::sqrt(gravity / std::max(com_height, 0.01)); }

LipState lipPredict(const LipState& now, double lambda, double t) {
  const double c = std::cosh(lambda * t), s = std::sinh(lambda * t);
  return {now.x * c + now.xd / lambda * s, now.x * lambda * s + now.xd * c};
}

double hlipPreImpactSpeed(double v_avg, double lambda, double T_ssp, double T_dsp) {
  const double sigma1 = lambda / std::tanh(0.5 * lambda * T_ssp);
  const double u = v_avg * (T_ssp + T_dsp);
  return sigma1 * u / (2.0 + T_dsp * sigma1);
}

double footPlacement(double x_com, double xd_com, double xd_des, const FootPlacementParams& p) {
  const double offset = p.k_v * xd_com + p.k_p * (xd_com - xd_des);
  return x_com + std::clamp(offset, -p.max_offset_m, p.max_offset_m);
}

}  // namespace mft::planner
