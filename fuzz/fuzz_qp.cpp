// Fuzz target: a WBCQP v1 problem file (mft-qp solve FILE, mft-qp bench DIR) as the reader takes it, then what
// mft-qp does with it: a small problem is solved (the solver must end with a status, never crash or loop), and
// every problem read writes back (%.17g) and reads again to the same text.
#include <cstdio>

#include "fuzz/fuzz_target.hpp"
#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_solver.hpp"

namespace mft::fuzz {

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  const std::string origin = "fuzz-input";
  qp::QpInstance inst;
  try {
    inst = qp::parseQpInstance(bytesText(data, size), origin);
  } catch (const qp::QpIoError& e) {
    return refusedWith(e.what(), origin);
  }
  const std::string text = qp::formatQpInstance(inst);
  if (qp::formatQpInstance(qp::parseQpInstance(text, "its own writing")) != text)
    throw std::logic_error("an instance written back does not read back to the same text");
  const qp::QpProblem& p = inst.problem;
  std::string status = "not solved (large)";
  if (p.n <= 24 && p.neq <= 24 && p.nin <= 24) {
    qp::GoldfarbIdnaniSolver solver(p.n, p.neq, p.nin);
    qp::QpSolution solution;
    status = qp::toString(solver.solve(p, &solution));
  }
  char what[160];
  std::snprintf(what, sizeof what, "n %d, neq %d, nin %d: %s", p.n, p.neq, p.nin, status.c_str());
  return acceptedAs(what);
}

}  // namespace mft::fuzz
