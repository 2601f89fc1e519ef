#pragma once
// Reader and writer of the WBCQP v1 text format (docs/reference/qp-instances.md#file-format). Numbers are written with %.17g, so a
// write/read round trip is bit-exact; inf / -inf are accepted. Malformed input (unknown record, wrong size, bad
// number, missing record, duplicate, text after "end") throws QpIoError whose message names the file.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "wbc/qp/qp_problem.hpp"

namespace mft::qp {

struct QpIoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct QpBlock {
  std::string name;
  int first = 0, length = 0;
};

struct QpInstance {
  QpProblem problem;  // dense_block is detected from H on reading
  std::string name;
  std::optional<long long> step;
  std::vector<QpBlock> varblocks, rowblocks;
  std::optional<Eigen::VectorXd> x_ref;
  std::optional<double> f_ref;
  std::optional<Eigen::VectorXi> active_ref;  // length n + nin, docs/reference/qp-instances.md#file-format convention
};

// Reading refuses, besides malformed text: a directory or other non-regular file, a file over kMaxFileBytes,
// dims that need more numbers than the file holds (nothing is allocated for them), non-finite H, g, Aeq, beq
// or Ain, and an H that is not symmetric within kSymmetryTolerance x max|H| (a solver uses one triangle).
constexpr std::size_t kMaxFileBytes = 256u << 20;
constexpr double kSymmetryTolerance = 1e-9;
QpInstance readQpInstance(const std::string& path);
// The data checks of reading, for a problem built otherwise: throws QpIoError naming `source`.
void checkProblemData(const QpProblem& p, const std::string& source);
// source names the text in error messages.
QpInstance parseQpInstance(const std::string& text, const std::string& source);
std::string formatQpInstance(const QpInstance& instance);
void writeQpInstance(const std::string& path, const QpInstance& instance);

// The *.txt files of a folder in file-name order (throws QpIoError if the folder cannot be read).
std::vector<std::string> listQpInstanceFiles(const std::string& dir);

}  // namespace mft::qp
