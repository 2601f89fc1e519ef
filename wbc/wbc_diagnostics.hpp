#pragma once
// Per-tick record of the whole-body controller (mirrors the WbcDiagnostics topic, plus the solution).
#include <array>
#include <cstdint>
#include <limits>

#include "model/coordinates.hpp"
#include "wbc/qp/qp_problem.hpp"
#include "wbc/safety_stage.hpp"

namespace mft::wbc {

constexpr int kMaxDiagTasks = 12;

struct WbcDiagnostics {
  std::uint64_t tick = 0;
  bool qp_attempted = false;  // false when the input was rejected before the QP
  qp::QpStatus status = qp::QpStatus::NumericalFailure;
  int iterations = 0;
  int active_constraints = 0;  // active bounds + active inequality rows (equalities not counted)
  double solve_time_us = 0.0;  // QP solver call only
  double tick_time_us = 0.0;   // whole update(): model, assembly, solve, inverse dynamics, safety
  double slack_norm = 0.0;     // ||eps||
  // Position tracking errors (reference - estimate): base z [m], base pitch [rad], right foot x, z, left
  // foot x, z [m] (the order of the WbcDiagnostics topic).
  std::array<double, 6> task_error{};
  // Acceleration-level residual || A x - b || of every cost term, in WholeBodyController::taskNames() order.
  std::array<double, kMaxDiagTasks> task_residual{};
  int num_tasks = 0;
  // MFT indices of the current configuration [right, left]: LTI from q; RACI [N/sqrt(kg)] from the hip angles
  // (docs/reference/five-bar-theory.md#acceleration-capacity-raci-and-leg-inertia), +inf at a singularity, NaN if the hips cannot close the loop.
  std::array<double, model::kNumLegs> lti{};
  std::array<double, model::kNumLegs> raci{{std::numeric_limits<double>::quiet_NaN(),
                                            std::numeric_limits<double>::quiet_NaN()}};
  // Largest violation of the MFT polytope max(A q_a - b) now and at the predicted q_a(t + dt) of the
  // solution (<= 0 inside). NaN without a polytope.
  double mft_violation = std::numeric_limits<double>::quiet_NaN();
  double mft_violation_predicted = std::numeric_limits<double>::quiet_NaN();
  bool torque_clamped = false;  // the (9) torques exceeded the limits by more than the solver tolerance
  // Solution of the tick (zeros when no solution was used).
  model::VectorQ qdd = model::VectorQ::Zero();
  model::VectorC f_c = model::VectorC::Zero();
  model::VectorA tau = model::VectorA::Zero();  // the command actually sent
  // Safety stage.
  SafetyMode safety_mode = SafetyMode::Normal;
  SafetyEvent safety_event = SafetyEvent::None;  // this tick's failure, None if it succeeded
  SafetyCounters safety;
};

}  // namespace mft::wbc
