#pragma once
// Robot acceleration capacity index (RACI, paper eq. 5) of one five-bar leg, as defined in docs/reference/five-bar-theory.md#acceleration-capacity-raci-and-leg-inertia:
// gamma_RACI = max_i tau~_i [N/sqrt(kg)], the worst normalized motor torque T_motor,i / sqrt(J_m) needed for any
// foot acceleration |a| <= a_max at zero velocity, with u_i = row i of J^-1 and w_i = row i of M_a J^-1.
//   optimal ratio (default): tau~_i* = a_max sqrt(2 (|u_i||w_i| + u_i.w_i) / eta_g)   (k chosen per configuration)
//   fixed drive:             tau~_i  = a_max || k u_i + w_i / (eta_g k) ||            (k = n sqrt(J_m))
// Gravity (optional) adds the holding torque g_i to the load side. A configuration at an input or output
// singularity needs unbounded torque: RACI is +infinity there (never NaN) and `singular` is set.
#include <string>

#include "model/mft_leg_inertia.hpp"

namespace mft::model {

enum class RaciForm { OptimalRatio, FixedDrive };
const char* raciFormName(RaciForm f);                 // "optimal" / "fixed"
bool parseRaciForm(const std::string& s, RaciForm* out);

struct RaciOptions {
  RaciForm form = RaciForm::OptimalRatio;
  double accel_max_mps2 = 60.0;   // desired foot acceleration bound a_max
  double drive_k = 0.3;           // k = n sqrt(J_m) [sqrt(kg) m], fixed-drive form only
  double gearbox_efficiency = 1.0;
  bool gravity = false;
  double gravity_mps2 = 9.81;
  // Drive constants from the robot description's actuator.
  static RaciOptions fromRobot(const RobotDescription& d);
};

// The actuator figure of merit rho = T_m,max / sqrt(J_m): the paper's RACI threshold (174.54 N/sqrt(kg)).
double actuatorRaciLimit(const ActuatorParams& a);

struct RaciResult {
  double raci = 0.0;       // max of the two
  double tau_rear = 0.0;   // tau~_r
  double tau_fore = 0.0;   // tau~_f
  bool singular = false;   // input or output singularity: all three are +infinity
};

RaciResult computeRaci(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p, const RaciOptions& o);

// J^-1 at a pose in the closed form of docs/reference/five-bar-theory.md#inverse-jacobian-in-closed-form (finite at output singularities, infinite at input ones).
Eigen::Matrix2d fiveBarInverseJacobian(const FiveBarGeometry& g, const FiveBarPose& p);

}  // namespace mft::model
