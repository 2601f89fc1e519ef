#include "violation_table.hpp"

#include <algorithm>
#include <cstdio>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "common/text_split.hpp"

namespace mft::tools {

namespace {

double number(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) throw std::runtime_error(where + ": '" + text + "' is not a number");
  return v;
}

std::string full(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

}  // namespace

ViolationTable violationTable(std::istream& in, const std::string& origin, const model::MftPolytope& p) {
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(origin + ": empty file");
  const auto header = config::splitOn(line, ',');
  const auto column = [&](const std::string& name) {
    return static_cast<int>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const int q[4] = {column("q4"), column("q6"), column("q8"), column("q10")};
  for (int c : q)
    if (c == static_cast<int>(header.size())) throw std::runtime_error(origin + ": needs the columns q4, q6, q8, q10");
  ViolationTable t;
  std::vector<int> passed;
  for (const char* name : {"stamp_ns", "time_s", "tick"})
    if (column(name) < static_cast<int>(header.size())) t.passed.push_back(name), passed.push_back(column(name));
  for (int number_of_line = 2; std::getline(in, line); ++number_of_line) {
    if (line.empty()) continue;
    const auto cells = config::splitOn(line, ',');
    const std::string where = origin + ":" + std::to_string(number_of_line);
    if (cells.size() != header.size()) throw std::runtime_error(where + ": " + std::to_string(cells.size()) + " cells, the header has " + std::to_string(header.size()));
    model::VectorA q_a;
    for (int i = 0; i < 4; ++i) q_a[i] = number(cells[static_cast<std::size_t>(q[i])], where);
    std::vector<std::string> row;
    for (int c : passed) row.push_back(cells[static_cast<std::size_t>(c)]);
    const double all = p.violation(q_a);
    row.push_back(full(p.legViolation(0, q_a)));
    row.push_back(full(p.legViolation(1, q_a)));
    row.push_back(full(all));
    t.max_violation = std::max(t.max_violation, all);
    t.rows.push_back(std::move(row));
  }
  return t;
}

void writeViolationCsv(std::ostream& out, const ViolationTable& t) {
  for (const auto& name : t.passed) out << name << ',';
  out << "mft_violation_right,mft_violation_left,mft_violation\n";
  for (const auto& row : t.rows) {
    for (std::size_t i = 0; i < row.size(); ++i) out << (i ? "," : "") << row[i];
    out << '\n';
  }
}

}  // namespace mft::tools
