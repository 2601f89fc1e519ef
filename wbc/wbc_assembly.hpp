#pragma once
// Generic assembly of the task and constraint lists into the pre-sized QpProblem (1/2 x'Hx + g'x with
// H = 2 sum w A'A, g = -2 sum w A'b, the WBCQP convention), and task residuals at a solution.
#include <Eigen/Core>

#include "wbc/qp/qp_problem.hpp"
#include "wbc/wbc_formulation.hpp"

namespace mft::wbc {

// Sizes the problem for the formulation (once, allocates).
void resizeProblem(const Formulation& f, qp::QpProblem* problem);
// Calls every term's update function.
void updateTerms(const TickContext& ctx, Formulation* f);
// Writes H, g, Aeq, beq, Ain, lbA, ubA, lb, ub. Sets dense_block = kNqdd when the f_c / eps part of H is
// diagonal (as the built-in terms make it), else 0. Allocation-free.
void assembleProblem(const Formulation& f, const VariableBounds& bounds, qp::QpProblem* problem);
// Task residuals || A x_block - b || into Task::residual.
void evaluateTaskResiduals(const Eigen::Ref<const Eigen::VectorXd>& x, Formulation* f);

}  // namespace mft::wbc
