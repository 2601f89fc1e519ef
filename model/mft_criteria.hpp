#pragma once
// The MFT preferable test of one leg configuration (paper Definition 1): reachable (loop closes, hips inside
// their limits, knees inside their hard stops, thighs not crossed) and every index inside its user range. Shared by the grids, the stance table,
// the index query and the tests so that all of them label a configuration the same way.
#include <string>

#include "model/five_bar.hpp"
#include "model/mft_indices.hpp"
#include "model/mft_raci.hpp"
#include "model/robot_description.hpp"

namespace mft::model {

struct MftLegModel {
  FiveBarGeometry geometry;
  LegInertiaParams inertia;
  Interval rear_hip, fore_hip, rear_knee, fore_knee;
  double foot_radius_m = 0.0;
  double knee_stop_margin_rad = 0.0;  // mechanical knee stops this far inside the knee limits
  static MftLegModel from(const RobotDescription& d);
};

struct MftCriteria {
  Interval lti{0.7, 1.0};
  Interval raci{0.0, 174.54};  // N/sqrt(kg)
  RaciOptions raci_options;
  // Paper defaults with the RACI limit and drive constants taken from the robot's actuator.
  static MftCriteria defaults(const RobotDescription& d);
};

struct LegEvaluation {
  FiveBarStatus status = FiveBarStatus::Unreachable;
  bool within_limits = false;  // hips and knees inside their limits
  bool reachable = false;      // status Ok and within limits
  TransmissionIndices indices;  // zeros when not Ok
  RaciResult raci;              // +infinity when not Ok or singular
  bool preferable = false;
  FiveBarPose pose;
};

LegEvaluation evaluateLegAt(const MftLegModel& m, const MftCriteria& c, double q_rear, double q_fore);
LegEvaluation evaluateLegAtFoot(const MftLegModel& m, const MftCriteria& c, const Eigen::Vector2d& foot);

// Vertical stance: foot straight below the hip axis at d = z_B - foot_radius (base frame on the hip axis).
LegEvaluation evaluateVerticalStance(const MftLegModel& m, const MftCriteria& c, double base_height_m);

// The base heights over flat ground at which a leg with its foot `foot_x_m` ahead of the hip axis (base
// frame, foot on the ground) is reachable: the loop closes and the hips and knees are inside their limits
// and knee stops (as for the MFT space). Scanned in `step_m` steps from 0 to l1 + l2 + foot radius; the
// reachable heights of a five-bar leg are one interval. lo > hi when no height is reachable.
Interval reachableBaseHeights(const MftLegModel& m, double foot_x_m, double step_m = 5e-4);

const char* fiveBarStatusName(FiveBarStatus s);

}  // namespace mft::model
