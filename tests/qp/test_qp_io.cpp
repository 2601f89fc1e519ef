// WBCQP v1 reader/writer: bit-exact round trip of the project's instance set (tests/data/qp), and loud failures on
// malformed files.
#include <gtest/gtest.h>

#include <ctime>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qp_instance_set.hpp"
#include "wbc/qp/qp_io.hpp"

using namespace mft::qp;

namespace {

std::string setFile(const char* name) { return mft::qp::testing::instanceDir() + "/" + name; }

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

template <class M>
bool bitEqual(const M& a, const M& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(typename M::Scalar) * static_cast<std::size_t>(a.size())) == 0;
}

void expectSame(const QpInstance& a, const QpInstance& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.step, b.step);
  const QpProblem &p = a.problem, &q = b.problem;
  EXPECT_EQ(p.n, q.n);
  EXPECT_EQ(p.neq, q.neq);
  EXPECT_EQ(p.nin, q.nin);
  EXPECT_EQ(p.dense_block, q.dense_block);
  EXPECT_TRUE(bitEqual(p.H, q.H) && bitEqual(p.g, q.g) && bitEqual(p.Aeq, q.Aeq) && bitEqual(p.beq, q.beq) &&
              bitEqual(p.Ain, q.Ain) && bitEqual(p.lbA, q.lbA) && bitEqual(p.ubA, q.ubA) && bitEqual(p.lb, q.lb) &&
              bitEqual(p.ub, q.ub));
  ASSERT_EQ(a.x_ref.has_value(), b.x_ref.has_value());
  if (a.x_ref) {
    EXPECT_TRUE(bitEqual(*a.x_ref, *b.x_ref));
  }
  ASSERT_EQ(a.f_ref.has_value(), b.f_ref.has_value());
  if (a.f_ref) {
    EXPECT_EQ(std::memcmp(&*a.f_ref, &*b.f_ref, sizeof(double)), 0);
  }
  ASSERT_EQ(a.active_ref.has_value(), b.active_ref.has_value());
  if (a.active_ref) {
    EXPECT_TRUE(bitEqual(*a.active_ref, *b.active_ref));
  }
  ASSERT_EQ(a.varblocks.size(), b.varblocks.size());
  ASSERT_EQ(a.rowblocks.size(), b.rowblocks.size());
}

// Parses text that must be refused; returns the error message.
std::string refusal(const std::string& text) {
  try {
    parseQpInstance(text, "bad_file.txt");
  } catch (const QpIoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return {};
}

const char* kSmall =
    "WBCQP 1\nname small\ndims 2 1 1\nH 2 2\n2 0\n0 1\ng 2\n1 -1\nAeq 1 2\n1 1\nbeq 1\n0.5\nAin 1 2\n1 -1\n"
    "lbA 1\n-inf\nubA 1\n3\nlb 2\n-inf 0\nub 2\ninf inf\nend\n";

// kSmall with the first `from` replaced by `to`.
std::string smallWith(const std::string& from, const std::string& to) {
  std::string s = kSmall;
  s.replace(s.find(from), from.size(), to);
  return s;
}

}  // namespace

TEST(QpIo, ReadsAnInstanceOfTheSet) {
  // The first single-support tick of the MFT-WBC stepping run: the right foot swings.
  const QpInstance inst = readQpInstance(setFile("step_mft_01000.txt"));
  EXPECT_EQ(inst.name, "step_mft_01000");
  EXPECT_EQ(inst.step, 1000);
  EXPECT_EQ(inst.problem.n, 27);
  EXPECT_EQ(inst.problem.neq, 7);
  EXPECT_EQ(inst.problem.nin, 20);
  // Detected from H: the qdd block is dense up to the last joint with an off-diagonal entry at this tick.
  EXPECT_EQ(inst.problem.dense_block, detectDenseBlock(inst.problem.H));
  EXPECT_GE(inst.problem.dense_block, 3);
  EXPECT_LE(inst.problem.dense_block, 11);
  ASSERT_EQ(inst.varblocks.size(), 3u);
  EXPECT_EQ(inst.varblocks[2].name, "eps");
  EXPECT_EQ(inst.rowblocks.size(), 5u);
  EXPECT_TRUE(inst.x_ref && inst.f_ref && inst.active_ref);
  EXPECT_EQ(inst.problem.lb[15], -kInf);
  EXPECT_EQ(inst.problem.ub[15], kInf);
  EXPECT_EQ(inst.problem.lb[12], inst.problem.ub[12]);  // swing foot f_z fixed
  EXPECT_EQ(inst.problem.lb[14], 0.0);                  // stance foot 0 <= f_z <= 1000 N
  EXPECT_EQ(inst.problem.ub[14], 1000.0);
}

TEST(QpIo, WriterReproducesTheSetFilesByteForByte) {
  for (const std::string& f : listQpInstanceFiles(mft::qp::testing::instanceDir())) {
    const std::string text = slurp(f);
    EXPECT_EQ(formatQpInstance(parseQpInstance(text, f)), text) << f;
  }
}

TEST(QpIo, RoundTripThroughAFileIsBitExact) {
  QpInstance a = readQpInstance(setFile("push_mft_03460.txt"));
  // Values %.6g would lose, infinities, and no optional records.
  a.problem.g[0] = 0.1 + 0.2;
  a.problem.beq[0] = -1e-300;
  a.problem.lbA[3] = -kInf;
  a.x_ref.reset();
  a.step.reset();
  const std::string path = (std::filesystem::temp_directory_path() / "mft_qp_roundtrip.txt").string();
  writeQpInstance(path, a);
  const QpInstance b = readQpInstance(path);
  expectSame(a, b);
  EXPECT_EQ(formatQpInstance(b), slurp(path));
  std::filesystem::remove(path);
  const QpInstance c = parseQpInstance(kSmall, "small");
  expectSame(c, parseQpInstance(formatQpInstance(c), "again"));
  EXPECT_EQ(c.problem.lb[1], 0.0);
  EXPECT_EQ(c.problem.lbA[0], -kInf);
}

TEST(QpIo, RefusesMalformedFilesNamingThem) {
  const std::string ok = kSmall;
  EXPECT_NO_THROW(parseQpInstance(ok, "ok"));
  const std::string msg = refusal(smallWith("ub 2", "wibble 3\nub 2"));
  EXPECT_NE(msg.find("bad_file.txt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown record 'wibble'"), std::string::npos) << msg;
  EXPECT_NE(refusal(smallWith("g 2\n1 -1", "g 3\n1 -1 2")).find("length 3"), std::string::npos);
  EXPECT_NE(refusal(smallWith("H 2 2\n2 0\n0 1", "H 2 1\n2\n0")).find("cols"), std::string::npos);
  EXPECT_NE(refusal(smallWith("end\n", "")).find("end"), std::string::npos);
  EXPECT_NE(refusal(ok + "extra\n").find("after 'end'"), std::string::npos);
  EXPECT_NE(refusal(smallWith("0.5", "0.5x")).find("0.5x"), std::string::npos);
  EXPECT_NE(refusal(smallWith("0.5", "nan")).find("nan"), std::string::npos);
  EXPECT_NE(refusal(smallWith("beq 1\n0.5\n", "")).find("missing record 'beq'"), std::string::npos);
  EXPECT_NE(refusal(smallWith("WBCQP 1", "WBCQP 2")).find("version"), std::string::npos);
  EXPECT_NE(refusal(smallWith("WBCQP 1", "QP 1")).find("WBCQP"), std::string::npos);
  EXPECT_NE(refusal(smallWith("g 2\n1 -1\n", "g 2\n1 -1\ng 2\n1 -1\n")).find("duplicate"), std::string::npos);
  EXPECT_FALSE(refusal(smallWith("ub 2\ninf inf\nend\n", "ub 2\ninf")).empty());  // truncated
  EXPECT_FALSE(refusal(smallWith("dims 2 1 1\n", "")).empty());
  try {
    readQpInstance("/nonexistent/dir/missing.txt");
    ADD_FAILURE();
  } catch (const QpIoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.txt"), std::string::npos);
  }
  EXPECT_THROW(listQpInstanceFiles("/nonexistent/dir"), QpIoError);
}

// Issue 16, item 8: data a solver cannot treat as a convex QP is refused on reading, and dims are bounded by
// what the file can hold before anything is allocated for them.
TEST(QpIo, RefusesAsymmetricOrNonFiniteDataAndImpossibleDims) {
  const std::string asym = refusal(smallWith("H 2 2\n2 0\n0 1", "H 2 2\n2 5\n0 1"));
  EXPECT_NE(asym.find("H is not symmetric: H(1,0) = 0 but H(0,1) = 5"), std::string::npos) << asym;
  // Within the relative tolerance (1e-9 x max|H|) is symmetric: rounding of a dumped H must pass.
  EXPECT_NO_THROW(parseQpInstance(smallWith("H 2 2\n2 0\n0 1", "H 2 2\n2 1e-12\n0 1"), "ok"));
  EXPECT_NE(refusal(smallWith("g 2\n1 -1", "g 2\ninf -1")).find("g has a non-finite entry"), std::string::npos);
  EXPECT_NE(refusal(smallWith("H 2 2\n2 0\n0 1", "H 2 2\n2 0\n0 -inf")).find("H has a non-finite entry"), std::string::npos);
  EXPECT_NE(refusal(smallWith("Aeq 1 2\n1 1", "Aeq 1 2\n1 inf")).find("Aeq has a non-finite entry"), std::string::npos);
  const std::clock_t t0 = std::clock();  // CPU time: allocating 80 GB of H would take seconds, or fail
  const std::string dims = refusal(smallWith("dims 2 1 1", "dims 100000 100000 100000"));
  EXPECT_LT(static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC, 0.1);
  EXPECT_NE(dims.find("need at least 30000000000 matrix entries, more than the file of"), std::string::npos) << dims;
}
