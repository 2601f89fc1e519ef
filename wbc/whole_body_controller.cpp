#include "wbc/whole_body_controller.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "model/mft_indices.hpp"
#include "wbc/wbc_assembly.hpp"

namespace mft::wbc {
namespace {

using Clock = std::chrono::steady_clock;
double microseconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

// Torques beyond the limit by more than this are reported as clamped (the QP bounds them up to its tolerance).
constexpr double kTorqueClampReportTol = 1e-6;

bool modelFinite(const model::ModelData& d) {
  return d.M.allFinite() && d.h.allFinite() && d.Jc.allFinite() && d.Jc_dot_qd.allFinite() && d.Jh.allFinite() &&
         d.Jh_dot_qd.allFinite() && d.foot_pos.allFinite() && d.foot_vel.allFinite();
}

WbcPolytope fromMftPolytope(const model::MftPolytope& p, const model::RobotDescription& robot) {
  if (p.robot_checksum != robot.checksum)
    throw std::invalid_argument("WBC: the MFT polytope " + p.source_file + " was made for robot description " +
                                model::checksumHex(p.robot_checksum) + ", not " + model::checksumHex(robot.checksum));
  WbcPolytope w;
  w.A = p.A;
  w.b = p.b;
  return w;
}

}  // namespace

WholeBodyController::WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config,
                                         const model::MftPolytope* polytope)
    : WholeBodyController(robot, config, polytope ? std::optional<WbcPolytope>(fromMftPolytope(*polytope, robot)) : std::nullopt,
                          polytope ? polytope->criteria.raci_options : model::MftCriteria::defaults(robot).raci_options) {}

WholeBodyController::WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config,
                                         const WbcPolytope& polytope)
    : WholeBodyController(robot, config, std::optional<WbcPolytope>(polytope),
                          model::MftCriteria::defaults(robot).raci_options) {}

WholeBodyController::WholeBodyController(const model::RobotDescription& robot, const WbcConfig& config,
                                         const std::optional<WbcPolytope>& polytope,
                                         const model::RaciOptions& raci_options)
    : model_(model::buildBipedModel(robot)),
      params_(makeWbcParams(robot, config, polytope ? &*polytope : nullptr)),
      has_polytope_(polytope.has_value()),
      total_mass_(robot.totalMass()),
      leg_geometry_(model::FiveBarGeometry::from(robot)),
      leg_inertia_(model::LegInertiaParams::from(robot)),
      raci_options_(raci_options),
      formulation_(buildFormulation(params_)),
      safety_(config.safety.hold_ticks, config.safety.damping_Nms_per_rad, params_.tau_max,
              config.safety.latch_damping) {
  if (static_cast<int>(formulation_.tasks.size()) > kMaxDiagTasks)
    throw std::invalid_argument("WBC: more cost terms than WbcDiagnostics::task_residual holds");
  resizeProblem(formulation_, &problem_);
  solver_.resize(kNx, formulation_.neq, formulation_.nin);
  // Pre-size the solution so the solver never has to.
  solution_.x = Eigen::VectorXd::Zero(kNx);
  solution_.active = Eigen::VectorXi::Zero(kNx + formulation_.nin);
  solution_.y_eq = Eigen::VectorXd::Zero(formulation_.neq);
  solution_.y_bounds = Eigen::VectorXd::Zero(kNx);
  solution_.y_rows = Eigen::VectorXd::Zero(formulation_.nin);
}

std::vector<std::string> WholeBodyController::taskNames() const {
  std::vector<std::string> names;
  for (const Task& t : formulation_.tasks) names.push_back(t.name);
  return names;
}

void WholeBodyController::resetSafety() {
  safety_.reset();
  have_fc_prev_ = false;
}

double WholeBodyController::polytopeViolation(const model::VectorA& q_a) const {
  if (!has_polytope_) return std::numeric_limits<double>::quiet_NaN();
  return model::polytopeViolation(params_.mft.A, params_.mft.b, q_a);
}

void WholeBodyController::fillStateDiagnostics(const model::RobotStateEstimate& state, const WbcReference& ref,
                                               bool model_valid, WbcDiagnostics* diag) const {
  diag->tick = state.tick;
  diag->safety_mode = safety_.mode();
  diag->safety = safety_.counters();
  diag->num_tasks = static_cast<int>(formulation_.tasks.size());
  if (!state.q.allFinite()) return;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    diag->lti[leg] = model::legTransmissionIndex(state.q, leg);
    // RACI depends on the hip angles only (docs/reference/five-bar-theory.md#acceleration-capacity-raci-and-leg-inertia); +inf at a singularity, NaN if unreachable.
    model::FiveBarPose pose;
    if (model::fiveBarForward(leg_geometry_, state.q[model::hipRearIndex(leg)], state.q[model::hipForeIndex(leg)],
                              &pose) == model::FiveBarStatus::Ok)
      diag->raci[leg] = model::computeRaci(leg_geometry_, leg_inertia_, pose, raci_options_).raci;
  }
  model::VectorA q_a;
  for (int i = 0; i < model::kNa; ++i) q_a[i] = state.q[model::kActuatedIndex[i]];
  diag->mft_violation = polytopeViolation(q_a);
  if (!model_valid) return;
  diag->task_error[0] = ref.base_z.pos - state.q[model::kBaseZ];
  diag->task_error[1] = ref.base_pitch.pos - state.q[model::kBasePitch];
  for (int i = 0; i < model::kNc; ++i) diag->task_error[2 + i] = ref.foot_pos[i] - data_.foot_pos[i];
}

model::ActuatorCommand WholeBodyController::fail(SafetyEvent cause, const model::RobotStateEstimate& state,
                                                 WbcDiagnostics* diag) {
  const model::ActuatorCommand cmd = safety_.reject(cause, state.tick, state.qd);
  if (diag) {
    diag->safety_event = cause;
    diag->safety_mode = safety_.mode();
    diag->safety = safety_.counters();
    diag->tau = cmd.tau;
  }
  return cmd;
}

model::ActuatorCommand WholeBodyController::update(const model::RobotStateEstimate& state, const WbcReference& ref,
                                                   WbcDiagnostics* diag_out) {
  const auto t_start = Clock::now();
  WbcDiagnostics scratch;  // on the stack: fixed-size only
  WbcDiagnostics* diag = diag_out ? diag_out : &scratch;
  *diag = WbcDiagnostics{};
  model::ActuatorCommand cmd;
  auto finish = [&](const model::ActuatorCommand& c) {
    diag->tick_time_us = microseconds(t_start, Clock::now());
    return c;
  };

  try {
    if (!state.q.allFinite() || !state.qd.allFinite() || !ref.allFinite()) {
      fillStateDiagnostics(state, ref, false, diag);
      return finish(fail(SafetyEvent::NonFiniteInput, state, diag));
    }

    // Model update: M, h, J_c, J_h and their Jdot qd, then the closure projection of (7)-(9).
    model::updateModel(model_, state.q, state.qd, &data_);
    model::closureProjection(data_, &proj_);
    if (!modelFinite(data_) || !computeDynamicsTerms(data_, proj_, &dyn_)) {
      fillStateDiagnostics(state, ref, false, diag);
      return finish(fail(SafetyEvent::ModelFailure, state, diag));
    }
    fillStateDiagnostics(state, ref, true, diag);

    // The force-rate term needs a previous force: start from the weight shared by the stance feet.
    if (!have_fc_prev_) {
      fc_prev_ = initialPreviousContactForce(total_mass_ * model_.gravity, ref.foot_in_stance);
      have_fc_prev_ = true;
    }

    // Assembly.
    TickContext ctx;
    ctx.params = &params_;
    ctx.state = &state;
    ctx.ref = &ref;
    ctx.model = &data_;
    ctx.dyn = &dyn_;
    ctx.fc_prev = fc_prev_;
    updateTerms(ctx, &formulation_);
    updateBounds(ctx, &bounds_);
    assembleProblem(formulation_, bounds_, &problem_);
    has_problem_ = true;
    problem_tick_ = state.tick;

    // Solve.
    diag->qp_attempted = true;
    const auto t_solve = Clock::now();
    const qp::QpStatus status = solver_.solve(problem_, &solution_);
    diag->solve_time_us = microseconds(t_solve, Clock::now());
    diag->status = status;
    diag->iterations = solution_.iterations;
    diag->active_constraints = static_cast<int>((solution_.active.array() != 0).count());
    if (status != qp::QpStatus::Optimal) return finish(fail(SafetyEvent::SolverFailure, state, diag));
    if (!solution_.x.allFinite()) return finish(fail(SafetyEvent::NonFiniteOutput, state, diag));

    const model::VectorQ qdd = solution_.x.segment<kNqdd>(0);
    const model::VectorC f_c = solution_.x.segment<kNfc>(kNqdd);
    diag->qdd = qdd;
    diag->f_c = f_c;
    diag->slack_norm = solution_.x.segment<kNeps>(kNqdd + kNfc).norm();
    evaluateTaskResiduals(solution_.x, &formulation_);
    for (std::size_t i = 0; i < formulation_.tasks.size(); ++i) diag->task_residual[i] = formulation_.tasks[i].residual;
    if (has_polytope_) {
      model::VectorA q_pred;
      for (int i = 0; i < model::kNa; ++i) {
        const int j = model::kActuatedIndex[i];
        q_pred[i] = predictedCoordinate(state.q[j], state.qd[j], qdd[j], params_.dt);
      }
      diag->mft_violation_predicted = polytopeViolation(q_pred);
    }

    // (9) decoded from the same matrices the QP's torque rows used, then the actuator limits (the QP keeps
    // tau inside them up to its tolerance).
    model::VectorA tau = model::actuatedTorque(dyn_.torque, qdd, f_c);
    if (!tau.allFinite()) return finish(fail(SafetyEvent::NonFiniteOutput, state, diag));
    for (int i = 0; i < model::kNa; ++i) {
      const double lim = params_.tau_max[i];
      if (std::abs(tau[i]) > lim * (1.0 + kTorqueClampReportTol)) diag->torque_clamped = true;
      tau[i] = std::max(-lim, std::min(lim, tau[i]));
    }
    fc_prev_ = f_c;

    cmd.tick = state.tick;
    cmd.tau = tau;
    cmd.mode = model::CommandMode::Normal;
    cmd = safety_.accept(cmd, state.qd);
    diag->tau = cmd.tau;
    diag->safety_mode = safety_.mode();
    diag->safety = safety_.counters();
    return finish(cmd);
  } catch (...) {
    return finish(fail(SafetyEvent::Exception, state, diag));
  }
}

}  // namespace mft::wbc
