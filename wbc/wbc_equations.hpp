#pragma once
// The paper's Problem 1 one equation at a time (RBDL style): plain data in, matrices out, one function per
// equation, numbered as published (docs/reference/theory.md). The WBC's terms (wbc_formulation.cpp) call these every tick;
// the tests call them directly. Rows are written over the whole QP variable x = [qdd (11) | f_c (4) | eps (12)]
// and sized here (fixed capacity: no allocation).
#include <Eigen/Core>
#include <array>

#include "model/coordinates.hpp"
#include "model/planar_dynamics.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/wbc_reference.hpp"
#include "wbc/wbc_terms.hpp"

namespace mft::wbc {

using PolytopeMatrix = Eigen::Matrix<double, kNeps, model::kNa>;  // A of (10), rows over q_a = [q4, q6, q8, q10]
using PolytopeVector = Eigen::Matrix<double, kNeps, 1>;

// Paper (12): a coordinate dt ahead under constant acceleration, q + qd dt + qdd dt^2 / 2. The MFT rows (13)-(14)
// and the SA-WBC rows (20) use it with the unknown qdd taken out (qdd = 0: the qdd term is the rows' matrix),
// the controller's diagnostics with the solved qdd.
inline double predictedCoordinate(double q, double qd, double qdd, double dt) { return q + qd * dt + 0.5 * qdd * dt * dt; }

// Paper (17): the PD task acceleration of one coordinate, xdd_des = xdd_ref + kp (x_ref - x) + kd (xd_ref - xd).
double pdAcceleration(const Setpoint1& ref, double pos, double vel, const PdGains1& gains);

// Paper (15a), a floating-base coordinate task (height or pitch): J_x = the unit row of coordinate `index`,
// Jdot_x qd = 0, so A = e_index' (1 x 11) and b = xdd_des.
void coordinateTaskRows(int index, double xdd_des, TaskMatrix* A, TaskVector* b);
// Paper (15a), a foot point task: A = the foot's two rows of J_c (2 x 11), b = xdd_des - Jdot_c qd.
void footTaskRows(const model::MatrixCQ& Jc, const model::VectorC& Jc_dot_qd, int leg, const Eigen::Vector2d& xdd_des,
                  TaskMatrix* A, TaskVector* b);
// Paper (15b), first term ||f_c||^2: A = I (4 x 4), b = 0.
void contactForceTaskRows(TaskMatrix* A, TaskVector* b);
// Paper (15b), second term ||f_c - f_c^-||^2: A = I, b = f_c^-, the contact forces of the last solved tick.
void contactForceRateTaskRows(const model::VectorC& fc_prev, TaskMatrix* A, TaskVector* b);
// The f_c^- of (15b) before any tick was solved: the weight shared equally by the stance feet (f_z only).
model::VectorC initialPreviousContactForce(double weight_N, const std::array<bool, model::kNumLegs>& stance);
// Paper (15c), ||eps||^2: A = I (12 x 12), b = 0.
void slackTaskRows(TaskMatrix* A, TaskVector* b);

// Paper (8) = (16a), the floating-base rows of (7): S_f M qdd - S_f N_h' J_c' f_c = -S_f N_h' H (3 rows). The
// J_h' term is dropped: the closure gap is between two chains of one leg, which the base moves alike, so S_f J_h'
// is zero (up to rounding). base_NhT = S_f N_h' (model::projectedDynamicsRows with model::kBaseIndex).
void baseDynamicsRows(const model::MatrixQ& M, const model::VectorQ& H, const model::MatrixCQ& Jc,
                      const Eigen::Matrix<double, 3, model::kNq>& base_NhT, ConstraintMatrix* A, ConstraintVector* rhs);
// The second block row of (6), the loop closure at acceleration level: J_h qdd = -Jdot_h qd (4 rows).
void loopClosureRows(const model::MatrixHQ& Jh, const model::VectorH& Jh_dot_qd, ConstraintMatrix* A,
                     ConstraintVector* rhs);
// Paper (16b), the friction pyramid U f_c <= 0: +f_x - mu f_z <= 0 and -f_x - mu f_z <= 0 per foot (4 rows).
void frictionPyramidRows(double mu, ConstraintMatrix* A, ConstraintVector* lower, ConstraintVector* upper);
// Paper (16c), tau_min <= tau_a <= tau_max with tau_a = tau_qdd qdd + tau_fc f_c + tau_0 of (9) (4 rows).
void torqueLimitRows(const model::ActuatedTorqueMap& torque, const model::VectorA& tau_max, ConstraintMatrix* A,
                     ConstraintVector* lower, ConstraintVector* upper);
// Paper (16e) = (11) with (13)-(14), the MFT rows C qdd - eps <= d (12 rows): J = S_a, Jdot qd = 0, so
// C = dt^2/2 A S_a and d = b - A (q_a + qd_a dt), the polytope (10) at the Taylor prediction (12).
void mftPolytopeRows(const PolytopeMatrix& A_poly, const PolytopeVector& b_poly, const model::VectorQ& q,
                     const model::VectorQ& qd, double dt, ConstraintMatrix* A, ConstraintVector* lower,
                     ConstraintVector* upper);
// Paper (20), SA-WBC: q_ua_min <= S_ua (q + qd dt + qdd dt^2 / 2) <= q_ua_max (4 rows). Not in the paper: a
// bound needing more than the qdd box can change in dt (dt^2/2 qdd_joint_max) is clipped to it, so an estimate
// already past a boundary asks for the strongest correction instead of making the QP infeasible.
void passiveJointRows(const model::VectorQ& q, const model::VectorQ& qd, double dt, const model::VectorA& passive_lo,
                      const model::VectorA& passive_hi, double qdd_joint_max, ConstraintMatrix* A,
                      ConstraintVector* lower, ConstraintVector* upper);

// Paper (16d), the acceleration box -qdd_max <= qdd <= qdd_max (base and joint limits).
void accelerationBounds(const Eigen::Vector3d& qdd_base_max, double qdd_joint_max, VariableBounds* bounds);
// The bounds half of (16b): 0 <= f_z <= f_z_max for a stance foot, f_z = 0 (hence f_x = 0 through the pyramid)
// for a swing foot; f_x free (the pyramid limits it).
void contactForceBounds(const std::array<bool, model::kNumLegs>& stance, double fz_max, VariableBounds* bounds);
// The eps of (16e): free when the MFT rows exist (soft constraint), fixed to 0 otherwise.
void slackBounds(bool soft_mft, VariableBounds* bounds);

}  // namespace mft::wbc
