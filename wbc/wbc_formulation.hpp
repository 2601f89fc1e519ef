#pragma once
// The terms of Problem 1 (paper (15)-(17), (11)-(14), (20)): which tasks and constraints exist for a variant and
// how each is refreshed from the tick's state, reference and dynamics. This is the one place to add a term.
#include <Eigen/Core>
#include <vector>

#include "model/coordinates.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/wbc_dynamics.hpp"
#include "wbc/wbc_equations.hpp"
#include "wbc/wbc_reference.hpp"
#include "wbc/wbc_terms.hpp"

namespace mft::wbc {

// MFT preferable polytope in actuated joint space: A q_a <= b, q_a = [q4, q6, q8, q10] (paper: 12 x 4).
struct WbcPolytope {
  PolytopeMatrix A = PolytopeMatrix::Zero();
  PolytopeVector b = PolytopeVector::Zero();
};

// Constants derived once from the robot, the config and the polytope.
struct WbcParams {
  WbcVariant variant = WbcVariant::Mft;
  double dt = 0.05;  // prediction horizon of (13)-(14) and (20) [s]
  WbcWeights weights;
  WbcGains gains;
  model::VectorA tau_max = model::VectorA::Zero();  // symmetric actuated torque limits [N m]
  double mu = 0.6;
  double fz_max = 1000.0;
  Eigen::Vector3d qdd_base_max{20.0, 20.0, 20.0};
  double qdd_joint_max = 22.0;
  WbcPolytope mft;
  model::VectorA passive_lo = model::VectorA::Zero(), passive_hi = model::VectorA::Zero();  // (20), S_ua order
};
// Throws std::invalid_argument if the variant needs a polytope and none is given, or it is not finite.
WbcParams makeWbcParams(const model::RobotDescription& robot, const WbcConfig& config, const WbcPolytope* polytope);

// Everything a term may read during one tick.
struct TickContext {
  const WbcParams* params = nullptr;
  const model::RobotStateEstimate* state = nullptr;
  const WbcReference* ref = nullptr;
  const model::ModelData* model = nullptr;
  const DynamicsTerms* dyn = nullptr;
  model::VectorC fc_prev = model::VectorC::Zero();  // contact forces of the last successful tick
};

struct Formulation {
  std::vector<Task> tasks;
  std::vector<Constraint> constraints;
  int neq = 0, nin = 0;  // rows, once laid out
};

// Builds the task and constraint lists of Problem 1 for params.variant, with row offsets laid out
// (equalities in list order into Aeq, inequalities into Ain).
Formulation buildFormulation(const WbcParams& params);

// Variable bounds: qdd box (16d), 0 <= f_z <= fmax (0 for a swing foot), f_x free, eps free (mft) or 0.
void updateBounds(const TickContext& ctx, VariableBounds* bounds);

// Indices of well-known tasks in Formulation::tasks (diagnostics read the residuals by name).
int findTask(const Formulation& f, const std::string& name);
int findConstraint(const Formulation& f, const std::string& name);

}  // namespace mft::wbc
