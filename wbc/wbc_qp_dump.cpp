// WholeBodyController::writeLastQp: the last tick's QP in the WBCQP v1 format (docs/reference/qp-instances.md#file-format).
#include <cstdio>
#include <stdexcept>

#include "wbc/qp/qp_io.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft::wbc {

void WholeBodyController::writeLastQp(const std::string& path, const std::string& name) const {
  if (!has_problem_) throw std::runtime_error("WBC: no QP has been assembled yet, nothing to write to " + path);
  qp::QpInstance inst;
  inst.problem = problem_;
  char default_name[32];
  std::snprintf(default_name, sizeof default_name, "wbc_%05llu", static_cast<unsigned long long>(problem_tick_));
  inst.name = name.empty() ? std::string(default_name) : name;
  inst.step = static_cast<long long>(problem_tick_);
  for (VarBlock b : {VarBlock::Qdd, VarBlock::Fc, VarBlock::Eps})
    inst.varblocks.push_back({toString(b), blockOffset(b), blockSize(b)});
  for (const Constraint& k : formulation_.constraints) inst.rowblocks.push_back({k.name, k.row_offset, k.rows()});
  // The solution is the reference only if this tick's solve ended optimal (the problem may be newer otherwise).
  if (solution_.status == qp::QpStatus::Optimal && solution_.x.size() == problem_.n) {
    inst.x_ref = solution_.x;
    inst.f_ref = solution_.objective;
    inst.active_ref = solution_.active;
  }
  qp::writeQpInstance(path, inst);
}

}  // namespace mft::wbc
