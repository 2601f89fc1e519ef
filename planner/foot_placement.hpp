#pragma once
// Paper (19) and its inputs: the linear inverted pendulum (LIP) prediction of the pre-impact CoM state and the
// desired pre-impact CoM speed of the H-LIP period-1 orbit for an average speed (Xiong & Ames 2019).
#include "planner/planner_config.hpp"

namespace mft::planner {

struct LipState {
  double x = 0.0;   // CoM x relative to the stance foot [m]
  double xd = 0.0;  // CoM x rate [m/s]
};

// lambda = sqrt(g / h), h = CoM height above the stance foot (clamped to >= 1 cm).
double lipLambda(double gravity, double com_height);

// Closed-form LIP flow xdd = lambda^2 x over t seconds.
LipState lipPredict(const LipState& now, double lambda, double t);

// Pre-impact CoM speed of the H-LIP period-1 orbit with average speed v_avg, swing (single-support) duration
// T_ssp and double support T_dsp: step length u = v_avg (T_ssp + T_dsp), x- = u / (2 + T_dsp sigma1),
// v- = sigma1 x-, sigma1 = lambda coth(lambda T_ssp / 2).
double hlipPreImpactSpeed(double v_avg, double lambda, double T_ssp, double T_dsp);

// (19): x_sw = x_C- + k_v xd_C- + k_p (xd_C- - xd_C-*), all world x; the offset x_sw - x_C- is clamped to
// +-max_offset_m so that the target stays within reach.
double footPlacement(double x_com, double xd_com, double xd_des, const FootPlacementParams& p);

}  // namespace mft::planner
