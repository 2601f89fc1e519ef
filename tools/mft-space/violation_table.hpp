#pragma once
// `mft-space violation`: a recorded run's actuated joint angles to the MFT polytope violation per sample.
#include <iosfwd>
#include <string>
#include <vector>

#include "model/mft_polytope.hpp"

namespace mft::tools {

struct ViolationTable {
  std::vector<std::string> passed;             // the input columns copied through (stamp_ns, time_s, tick)
  std::vector<std::vector<std::string>> rows;  // per row: the passed values, then right, left, augmented
  double max_violation = -1e300;               // of the augmented column
};

// Reads a CSV with a header naming q4, q6, q8 and q10 (others ignored); throws std::runtime_error naming
// `origin` and the line for a missing column or a bad number.
ViolationTable violationTable(std::istream& in, const std::string& origin, const model::MftPolytope& p);
void writeViolationCsv(std::ostream& out, const ViolationTable& t);

}  // namespace mft::tools
