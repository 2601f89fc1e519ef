#include "wbc/wbc_assembly.hpp"

namespace mft::wbc {

void resizeProblem(const Formulation& f, qp::QpProblem* problem) { problem->resize(kNx, f.neq, f.nin); }

void updateTerms(const TickContext& ctx, Formulation* f) {
  for (Task& t : f->tasks)
    if (t.update) t.update(ctx, &t);
  for (Constraint& k : f->constraints)
    if (k.update) k.update(ctx, &k);
}

void assembleProblem(const Formulation& f, const VariableBounds& bounds, qp::QpProblem* problem) {
  qp::QpProblem& p = *problem;
  p.H.setZero();
  p.g.setZero();
  for (const Task& t : f.tasks) {
    if (t.weight == 0.0) continue;
    const int off = blockOffset(t.block);
    const int n = blockSize(t.block);
    // Fixed-capacity temporaries: the products below stay on the stack.
    TaskMatrix AtA(n, n);
    AtA.noalias() = t.A.transpose() * t.A;
    TaskVector Atb(n);
    Atb.noalias() = t.A.transpose() * t.b;
    p.H.block(off, off, n, n) += (2.0 * t.weight) * AtA;
    p.g.segment(off, n) -= (2.0 * t.weight) * Atb;
  }
  for (const Constraint& k : f.constraints) {
    if (k.type == Constraint::Type::Equality) {
      p.Aeq.middleRows(k.row_offset, k.rows()) = k.A;
      p.beq.segment(k.row_offset, k.rows()) = k.lower;
    } else {
      p.Ain.middleRows(k.row_offset, k.rows()) = k.A;
      p.lbA.segment(k.row_offset, k.rows()) = k.lower;
      p.ubA.segment(k.row_offset, k.rows()) = k.upper;
    }
  }
  p.lb = bounds.lb;
  p.ub = bounds.ub;
  // The solver's block-diagonal shortcut is valid only if nothing couples f_c / eps entries in H.
  const auto rest = p.H.bottomRightCorner(kNx - kNqdd, kNx - kNqdd);
  bool diagonal = p.H.block(0, kNqdd, kNqdd, kNx - kNqdd).isZero(0.0);
  for (int j = 0; diagonal && j < rest.cols(); ++j)
    for (int i = 0; i < rest.rows(); ++i)
      if (i != j && rest(i, j) != 0.0) {
        diagonal = false;
        break;
      }
  p.dense_block = diagonal ? kNqdd : 0;
}

void evaluateTaskResiduals(const Eigen::Ref<const Eigen::VectorXd>& x, Formulation* f) {
  for (Task& t : f->tasks) {
    TaskVector r(t.rows());
    r.noalias() = t.A * x.segment(blockOffset(t.block), blockSize(t.block));
    r -= t.b;
    t.residual = r.norm();
  }
}

}  // namespace mft::wbc
