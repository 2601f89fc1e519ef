#include "wbc/qp/qp_io.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace mft::qp {
namespace {

class Tokens {
 public:
  Tokens(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw QpIoError(source_ + ": " + what + " (near token " + std::to_string(count_) + ")");
  }
  bool atEnd() {
    skipSpace();
    return pos_ >= text_.size();
  }
  std::string word(const char* what) {
    skipSpace();
    if (pos_ >= text_.size()) fail(std::string("unexpected end of file, expected ") + what);
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    ++count_;
    return text_.substr(start, pos_ - start);
  }
  std::size_t textSize() const { return text_.size(); }
  long long integer(const char* what) {
    const std::string w = word(what);
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(w.c_str(), &end, 10);
    if (w.empty() || *end != '\0' || errno != 0) fail(std::string("expected an integer for ") + what + ", got '" + w + "'");
    return v;
  }
  double number(const char* what) {
    const std::string w = word(what);
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (w.empty() || *end != '\0' || std::isnan(v)) fail(std::string("expected a number for ") + what + ", got '" + w + "'");
    return v;
  }

 private:
  void skipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  const std::string& text_;
  const std::string& source_;
  std::size_t pos_ = 0;
  long long count_ = 0;
};

void expectSize(Tokens& t, const std::string& key, long long got, long long want, const char* which) {
  if (got != want)
    t.fail("record '" + key + "' has " + which + " " + std::to_string(got) + ", dims require " + std::to_string(want));
}

void readMatrix(Tokens& t, const std::string& key, Eigen::MatrixXd& m, int rows, int cols) {
  expectSize(t, key, t.integer("rows"), rows, "rows");
  expectSize(t, key, t.integer("cols"), cols, "cols");
  m.resize(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = t.number(key.c_str());
}

void readVector(Tokens& t, const std::string& key, Eigen::VectorXd& v, int len) {
  expectSize(t, key, t.integer("length"), len, "length");
  v.resize(len);
  for (int i = 0; i < len; ++i) v[i] = t.number(key.c_str());
}

// The problem's data records in file order: a matrix of `rows` x n or a vector of `rows` entries (rows from dims).
struct DataRecord {
  const char* key;
  Eigen::MatrixXd QpProblem::*matrix;  // null for a vector
  Eigen::VectorXd QpProblem::*vector;  // null for a matrix
  int QpProblem::*rows;
};
const DataRecord kDataRecords[] = {
    {"H", &QpProblem::H, nullptr, &QpProblem::n},       {"g", nullptr, &QpProblem::g, &QpProblem::n},
    {"Aeq", &QpProblem::Aeq, nullptr, &QpProblem::neq}, {"beq", nullptr, &QpProblem::beq, &QpProblem::neq},
    {"Ain", &QpProblem::Ain, nullptr, &QpProblem::nin}, {"lbA", nullptr, &QpProblem::lbA, &QpProblem::nin},
    {"ubA", nullptr, &QpProblem::ubA, &QpProblem::nin}, {"lb", nullptr, &QpProblem::lb, &QpProblem::n},
    {"ub", nullptr, &QpProblem::ub, &QpProblem::n}};

const DataRecord* dataRecord(const std::string& key) {
  for (const DataRecord& r : kDataRecords)
    if (key == r.key) return &r;
  return nullptr;
}

void appendNumber(std::string& out, double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);  // prints inf / -inf for infinities
  out += buf;
}

void appendVector(std::string& out, const char* key, const Eigen::VectorXd& v) {
  out += key;
  out += ' ' + std::to_string(v.size()) + '\n';
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i) out += ' ';
    appendNumber(out, v[i]);
  }
  out += '\n';
}

void appendMatrix(std::string& out, const char* key, const Eigen::MatrixXd& m) {
  out += std::string(key) + ' ' + std::to_string(m.rows()) + ' ' + std::to_string(m.cols()) + '\n';
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      if (j) out += ' ';
      appendNumber(out, m(i, j));
    }
    out += '\n';
  }
}

}  // namespace

QpInstance parseQpInstance(const std::string& text, const std::string& source) {
  Tokens t(text, source);
  if (t.word("magic") != "WBCQP") t.fail("not a WBCQP file (first token must be 'WBCQP')");
  const long long version = t.integer("version");
  if (version != 1) t.fail("unsupported WBCQP version " + std::to_string(version) + " (this reader knows 1)");

  QpInstance inst;
  QpProblem& p = inst.problem;
  bool have_dims = false, ended = false;
  std::set<std::string> seen;
  const std::set<std::string> repeatable = {"varblock", "rowblock"};
  const std::set<std::string> known = {"name", "step", "dims", "varblock", "rowblock", "H", "g", "Aeq", "beq", "Ain",
                                       "lbA", "ubA", "lb", "ub", "x_ref", "f_ref", "active_ref", "end"};
  while (!t.atEnd()) {
    const std::string key = t.word("record");
    if (!known.count(key)) t.fail("unknown record '" + key + "'");
    if (!repeatable.count(key) && !seen.insert(key).second) t.fail("duplicate record '" + key + "'");
    const bool sized = key != "name" && key != "step" && key != "dims" && key != "end" && key != "f_ref";
    if (sized && !repeatable.count(key) && !have_dims) t.fail("record '" + key + "' before 'dims'");
    if (key == "end") {
      ended = true;
      break;
    } else if (key == "name") {
      inst.name = t.word("name");
    } else if (key == "step") {
      inst.step = t.integer("step");
    } else if (key == "dims") {
      const long long n = t.integer("n"), neq = t.integer("neq"), nin = t.integer("nin");
      if (n < 0 || neq < 0 || nin < 0 || n > 100000 || neq > 100000 || nin > 100000) t.fail("implausible dims");
      // Bound what the dims make us allocate by what the file can hold: H, Aeq and Ain alone need
      // (n + neq + nin) n numbers of at least two characters each ("0 ").
      const double numbers = static_cast<double>(n + neq + nin) * static_cast<double>(n);
      if (2.0 * numbers > static_cast<double>(t.textSize()))
        t.fail("dims n " + std::to_string(n) + ", neq " + std::to_string(neq) + ", nin " + std::to_string(nin) +
               " need at least " + std::to_string(static_cast<long long>(numbers)) +
               " matrix entries, more than the file of " + std::to_string(t.textSize()) + " bytes can hold");
      p.resize(static_cast<int>(n), static_cast<int>(neq), static_cast<int>(nin));
      have_dims = true;
    } else if (key == "varblock" || key == "rowblock") {
      QpBlock b;
      b.name = t.word("block name");
      b.first = static_cast<int>(t.integer("block first"));
      b.length = static_cast<int>(t.integer("block length"));
      if (b.first < 0 || b.length < 0) t.fail("negative " + key + " '" + b.name + "'");
      (key == "varblock" ? inst.varblocks : inst.rowblocks).push_back(b);
    } else if (const DataRecord* r = dataRecord(key)) {
      if (r->matrix) readMatrix(t, key, p.*(r->matrix), p.*(r->rows), p.n);
      else readVector(t, key, p.*(r->vector), p.*(r->rows));
    } else if (key == "x_ref") {
      inst.x_ref.emplace();
      readVector(t, key, *inst.x_ref, p.n);
    } else if (key == "f_ref") {
      inst.f_ref = t.number("f_ref");
    } else if (key == "active_ref") {
      expectSize(t, key, t.integer("length"), p.n + p.nin, "length");
      Eigen::VectorXi a(p.n + p.nin);
      for (int i = 0; i < a.size(); ++i) {
        const long long v = t.integer("active_ref");
        if (v < -1 || v > 1) t.fail("active_ref entries must be -1, 0 or 1");
        a[i] = static_cast<int>(v);
      }
      inst.active_ref = a;
    }
  }
  if (!ended) t.fail("missing 'end' record");
  if (!t.atEnd()) t.fail("text after 'end'");
  for (const char* required : {"name", "dims"})
    if (!seen.count(required)) t.fail(std::string("missing record '") + required + "'");
  for (const DataRecord& r : kDataRecords)
    if (!seen.count(r.key)) t.fail(std::string("missing record '") + r.key + "'");
  for (const QpBlock& b : inst.varblocks)
    if (b.first + b.length > p.n) t.fail("varblock '" + b.name + "' exceeds n");
  checkProblemData(p, source);
  p.dense_block = detectDenseBlock(p.H);
  return inst;
}

void checkProblemData(const QpProblem& p, const std::string& source) {
  auto fail = [&](const std::string& what) { throw QpIoError(source + ": " + what); };
  auto finite = [&](const auto& m, const char* name) {
    for (Eigen::Index i = 0; i < m.size(); ++i)
      if (!std::isfinite(m.data()[i])) fail(std::string(name) + " has a non-finite entry (" + std::to_string(m.data()[i]) + ")");
  };
  finite(p.H, "H");
  finite(p.g, "g");
  finite(p.Aeq, "Aeq");
  finite(p.beq, "beq");
  finite(p.Ain, "Ain");
  const double scale = p.H.size() ? p.H.cwiseAbs().maxCoeff() : 0.0;
  for (int j = 0; j < p.n; ++j)
    for (int i = j + 1; i < p.n; ++i) {
      const double d = std::abs(p.H(i, j) - p.H(j, i));
      if (d > kSymmetryTolerance * scale) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "H is not symmetric: H(%d,%d) = %.17g but H(%d,%d) = %.17g (difference %.3g > %.0e x max|H| = %.3g)",
                      i, j, p.H(i, j), j, i, p.H(j, i), d, kSymmetryTolerance, kSymmetryTolerance * scale);
        fail(buf);
      }
    }
}

QpInstance readQpInstance(const std::string& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(st)) throw QpIoError(path + ": is a directory, not a WBCQP file");
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw QpIoError(path + ": not a regular file");
  if (std::filesystem::exists(st) && std::filesystem::file_size(path, ec) > kMaxFileBytes)
    throw QpIoError(path + ": " + std::to_string(std::filesystem::file_size(path, ec)) +
                    " bytes, more than a WBCQP instance can be (" + std::to_string(kMaxFileBytes) + " bytes at most)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw QpIoError(path + ": cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw QpIoError(path + ": read error");
  return parseQpInstance(ss.str(), path);
}

std::string formatQpInstance(const QpInstance& inst) {
  const QpProblem& p = inst.problem;
  std::string out;
  out.reserve(static_cast<std::size_t>(26) * (p.n * (p.n + p.neq + p.nin + 8) + 4 * p.nin) + 1024);
  out += "WBCQP 1\nname " + inst.name + '\n';
  if (inst.step) out += "step " + std::to_string(*inst.step) + '\n';
  out += "dims " + std::to_string(p.n) + ' ' + std::to_string(p.neq) + ' ' + std::to_string(p.nin) + '\n';
  for (const QpBlock& b : inst.varblocks)
    out += "varblock " + b.name + ' ' + std::to_string(b.first) + ' ' + std::to_string(b.length) + '\n';
  for (const QpBlock& b : inst.rowblocks)
    out += "rowblock " + b.name + ' ' + std::to_string(b.first) + ' ' + std::to_string(b.length) + '\n';
  for (const DataRecord& r : kDataRecords) {
    if (r.matrix) appendMatrix(out, r.key, p.*(r.matrix));
    else appendVector(out, r.key, p.*(r.vector));
  }
  if (inst.x_ref) appendVector(out, "x_ref", *inst.x_ref);
  if (inst.f_ref) {
    out += "f_ref ";
    appendNumber(out, *inst.f_ref);
    out += '\n';
  }
  if (inst.active_ref) {
    out += "active_ref " + std::to_string(inst.active_ref->size()) + '\n';
    for (Eigen::Index i = 0; i < inst.active_ref->size(); ++i) {
      if (i) out += ' ';
      out += std::to_string((*inst.active_ref)[i]);
    }
    out += '\n';
  }
  out += "end\n";
  return out;
}

void writeQpInstance(const std::string& path, const QpInstance& inst) {
  const std::string text = formatQpInstance(inst);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw QpIoError(path + ": cannot open for writing");
  out << text;
  out.flush();
  if (!out) throw QpIoError(path + ": write error");
}

std::vector<std::string> listQpInstanceFiles(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw QpIoError(dir + ": not a directory");
  std::vector<std::string> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".txt" && it->is_regular_file(ec)) files.push_back(it->path().string());
  if (ec) throw QpIoError(dir + ": " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace mft::qp
