#pragma once
// The MFT-WBC of the paper (Problem 1, (15)-(17)) with the SA-WBC baseline (20) and a no-MFT ablation,
// torques by the closed-loop inverse dynamics (9), and a safety stage. One update() per control tick;
// everything is sized at construction and nothing is allocated per tick.
//
//   const MftPolytope polytope = model::loadMftPolytope("config/mft_space.yaml", robot);
//   WholeBodyController wbc(robot, loadWbcConfig("config/wbc.yaml"), &polytope);
//   WbcDiagnostics diag;
//   ActuatorCommand cmd = wbc.update(state_estimate, reference, &diag);
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "model/mft_criteria.hpp"
#include "model/mft_polytope.hpp"
#include "model/planar_dynamics.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"
#include "wbc/qp/qp_problem.hpp"
#include "wbc/qp/qp_solver.hpp"
#include "wbc/safety_stage.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/wbc_diagnostics.hpp"
#include "wbc/wbc_dynamics.hpp"
#include "wbc/wbc_formulation.hpp"
#include "wbc/wbc_reference.hpp"
#include "wbc/wbc_tuning.hpp"

namespace mft::wbc {

class WholeBodyController {
 public:
  // polytope: the MFT preferable polytope of config/mft_space.yaml (required for variant mft, optional
  // otherwise: then only used for diagnostics; its RACI settings are used for the RACI diagnostics). Throws
  // mft::config::ConfigError for a config that does not fit the robot and std::invalid_argument for a missing
  // polytope or one made for another robot description.
  WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config,
                      const model::MftPolytope* polytope = nullptr);
  // Same with a bare A q_a <= b (tests, studies): no checksum to check; RACI settings from the robot.
  WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config, const WbcPolytope& polytope);

  // One control tick. Never throws and never returns non-finite torques: a failure goes to the safety stage.
  // diag may be null.
  model::ActuatorCommand update(const model::RobotStateEstimate& state, const WbcReference& ref,
                                WbcDiagnostics* diag);

  // Leaves a latched damping state and restarts the contact-force history.
  void resetSafety();

  // Live tuning: the weights and gains from the next update() on (copies doubles: allocation-free, for a tick
  // boundary). Judge a change with applyWbcOverride first (wbc_tuning.hpp).
  void setTuning(const WbcTuning& tuning) {
    params_.weights = tuning.weights;
    params_.gains = tuning.gains;
  }
  WbcTuning tuning() const { return {params_.weights, params_.gains}; }

  const WbcParams& params() const { return params_; }
  WbcVariant variant() const { return params_.variant; }
  const Formulation& formulation() const { return formulation_; }
  // Names of the cost terms, the order of WbcDiagnostics::task_residual.
  std::vector<std::string> taskNames() const;
  const SafetyStage& safety() const { return safety_; }

  // The QP of the last tick that got as far as assembly, its solution, and the model at that state.
  // lastProblemTick() is the tick of that problem (false/0 if none yet).
  bool hasLastProblem() const { return has_problem_; }
  std::uint64_t lastProblemTick() const { return problem_tick_; }
  const qp::QpProblem& lastProblem() const { return problem_; }
  const qp::QpSolution& lastSolution() const { return solution_; }
  const model::ModelData& modelData() const { return data_; }
  const DynamicsTerms& dynamicsTerms() const { return dyn_; }
  const model::PlanarModel& planarModel() const { return model_; }

  // Writes the last tick's QP in the WBCQP v1 format (docs/reference/qp-instances.md#file-format) with named variable and
  // row blocks, and the solution as x_ref/f_ref/active_ref if it was optimal. The instance is named `name`
  // (default wbc_<tick>). Call right after update() of the tick to dump (from a non-realtime thread: it
  // allocates and does file I/O). Throws std::runtime_error if there is no problem yet or the file cannot be
  // written.
  void writeLastQp(const std::string& path, const std::string& name = {}) const;

 private:
  WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config,
                      const std::optional<WbcPolytope>& polytope, const model::RaciOptions& raci_options);
  model::ActuatorCommand fail(SafetyEvent cause, const model::RobotStateEstimate& state, WbcDiagnostics* diag);
  void fillStateDiagnostics(const model::RobotStateEstimate& state, const WbcReference& ref, bool model_valid,
                            WbcDiagnostics* diag) const;
  double polytopeViolation(const model::VectorA& q_a) const;

  model::PlanarModel model_;
  WbcParams params_;
  bool has_polytope_ = false;
  double total_mass_ = 0.0;
  model::FiveBarGeometry leg_geometry_;
  model::LegInertiaParams leg_inertia_;
  model::RaciOptions raci_options_;
  Formulation formulation_;
  VariableBounds bounds_;
  model::ModelData data_;
  model::ClosureProjection proj_;
  DynamicsTerms dyn_;
  qp::QpProblem problem_;
  qp::QpSolution solution_;
  qp::GoldfarbIdnaniSolver solver_;
  SafetyStage safety_;
  model::VectorC fc_prev_ = model::VectorC::Zero();
  bool have_fc_prev_ = false;
  bool has_problem_ = false;
  std::uint64_t problem_tick_ = 0;
};

}  // namespace mft::wbc
