// The mft-space command line: bad arguments and bad configuration exit with code 2 and a message, never a
// crash; `index --json` answers for one configuration.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "model/mft_polytope.hpp"

namespace {
struct CliRun {
  int code = -1;
  std::string out, err;
};
CliRun run(const std::string& args) {
  // Per-process names: CTest may run these tests in parallel (ctest -j).
  const std::string dir = ::testing::TempDir() + "/mft_cli_" + std::to_string(getpid());
  const std::string out = dir + "_out.txt", err = dir + "_err.txt";
  const std::string cmd = std::string(MFT_BIN_DIR) + "/mft-space " + args + " > " + out + " 2> " + err;
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}
void expectUsage(const std::string& args, const std::string& message) {
  const CliRun r = run(args);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << args << "\nstderr: " << r.err;
}
}  // namespace

TEST(MftSpaceCli, BadArgumentsExitWithCode2) {
  expectUsage("", "missing command");
  expectUsage("frobnicate", "unknown command");
  expectUsage("index --rear 0.1", "missing required option --fore");
  expectUsage("index --rear abc --fore 0.5", "--rear expects a finite number");
  expectUsage("index --rear nan --fore 0.5", "--rear expects a finite number");
  expectUsage("index --rear 0.1 --fore", "--fore needs a value");
  expectUsage("index --rear 0.1 --fore 0.5 --bogus 3", "unknown option --bogus");
  expectUsage("index --rear 0.1 --fore 0.5 --raci-form best", "--raci-form");
  expectUsage("fit --joint-step -0.01 --output /dev/null", "--joint-step must be > 0");
  expectUsage("fit --joint-step 0.00001 --output /dev/null", "--joint-step must lie in");
  expectUsage("fit --edges 2 --output /dev/null", "--edges expects an integer in [3, 32]");
  expectUsage("fit --lti-min 0.9 --lti-max 0.5 --output /dev/null", "--lti-min must not exceed");
  expectUsage("all", "missing required option --out");
  expectUsage("stance --from 0.46 --to 0.38", "--to must not be below --from");
  expectUsage("stance extra", "unexpected argument 'extra'");
}

TEST(MftSpaceCli, BadConfigExitsWithCode2) {
  expectUsage("index --rear 0.1 --fore 0.5 --robot /nonexistent/robot.yaml", "cannot open the file");
  const std::string bad = ::testing::TempDir() + "/mft_bad_space_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(bad) << "schema_version: 1\nrobot: {name: x}\n";
  expectUsage("stance --polytope " + bad, "bad configuration");
  std::ofstream(bad) << "not: [valid";
  expectUsage("stance --polytope " + bad, "not valid YAML");
}

TEST(MftSpaceCli, IndexPrintsLtiAndRaci) {
  const CliRun r = run("index --rear -0.6435 --fore 0.6435 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"lti\": 0.874"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"gamma_I\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"preferable\": true"), std::string::npos) << r.out;
  // A singular configuration answers with zeros and a null RACI, not NaN.
  const CliRun s = run("index --rear 0.2 --fore 0.2 --json");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("\"lti\": 0"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("\"raci\": null"), std::string::npos) << s.out;
  EXPECT_EQ(s.out.find("nan"), std::string::npos) << s.out;
}

TEST(MftSpaceCli, StanceTableMarksInsideAndOutside) {
  const CliRun r = run("stance --json --from 0.38 --to 0.46 --step 0.02");
  ASSERT_EQ(r.code, 0) << r.err;
  std::size_t count_in = 0, pos = 0;
  while ((pos = r.out.find("\"inside_polygon\": true", pos)) != std::string::npos) ++count_in, ++pos;
  EXPECT_EQ(count_in, 3u) << r.out;  // 0.38, 0.40, 0.42
}

TEST(MftSpaceCli, ViolationPerRowMatchesTheRowsWrittenOut) {
  // `violation` on a small CSV against the polytope's rows written out by hand (the columns it passes through,
  // each leg's rows, the augmented maximum), and its one-line errors.
  const mft::model::RobotDescription robot = mft::model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  const mft::model::MftPolytope p = mft::model::loadMftPolytope(std::string(MFT_CONFIG_DIR) + "/mft_space.yaml", robot);
  const std::string in = ::testing::TempDir() + "/mft_cli_q_" + std::to_string(getpid()) + ".csv";
  const double q[3][4] = {{-0.64, 0.64, -0.64, 0.64}, {0.3, 1.4, -0.9, 0.2}, {-1.5, -0.2, 0.1, 1.9}};
  {
    std::ofstream f(in);
    f << "stamp_ns,time_s,tick,x,q4,q6,q8,q10\n";
    for (int r = 0; r < 3; ++r) f << r * 1000000 << "," << r * 0.001 << "," << r << ",0," << q[r][0] << "," << q[r][1] << "," << q[r][2] << "," << q[r][3] << "\n";
  }
  const CliRun r = run("violation --csv " + in);
  ASSERT_EQ(r.code, 0) << r.err;
  std::stringstream lines(r.out);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "stamp_ns,time_s,tick,mft_violation_right,mft_violation_left,mft_violation");
  for (int row = 0; row < 3; ++row) {
    ASSERT_TRUE(std::getline(lines, line));
    double leg[2] = {-1e300, -1e300};
    for (int l = 0; l < 2; ++l)
      for (int k = 0; k < mft::model::kMftLegEdges; ++k)
        leg[l] = std::max(leg[l], p.leg.A(k, 0) * q[row][2 * l] + p.leg.A(k, 1) * q[row][2 * l + 1] - p.leg.b[k]);
    double tick = -1, right = 0, left = 0, all = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%*[^,],%*[^,],%lf,%lf,%lf,%lf", &tick, &right, &left, &all), 4) << line;
    EXPECT_EQ(tick, row);
    EXPECT_NEAR(right, leg[0], 1e-12);
    EXPECT_NEAR(left, leg[1], 1e-12);
    EXPECT_NEAR(all, std::max(leg[0], leg[1]), 1e-12);
  }
  {
    std::ofstream f(in);
    f << "tick,q4,q6,q8\n1,0,0,0\n";
  }
  const CliRun missing = run("violation --csv " + in);
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("needs the columns q4, q6, q8, q10"), std::string::npos) << missing.err;
  expectUsage("violation", "missing required option --csv");
  std::remove(in.c_str());
}
