// config/mft_space.yaml: the committed file is current for config/robot.yaml (checksum, and a re-fit by the
// built mft-space gives the same A and b), the strict loader refuses bad or stale files, and write/load
// round-trips.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <sstream>

#include "common/strict_yaml.hpp"
#include "model/mft_polytope.hpp"
#include "tests/support/config_test_support.hpp"

using mft::config::ConfigError;
using namespace mft::model;

namespace {
std::string robotPath() { return std::string(MFT_CONFIG_DIR) + "/robot.yaml"; }
std::string polytopePath() { return std::string(MFT_CONFIG_DIR) + "/mft_space.yaml"; }
using mft::test::readTextFile;
std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}
void expectError(const std::string& pattern, const std::string& replacement, const std::string& expect) {
  const RobotDescription robot = loadRobotDescription(robotPath());
  mft::test::expectConfigError(readTextFile(polytopePath()), pattern, replacement, "bad-space.yaml", expect,
                               [&](const std::string& text, const std::string& origin) {
                                 return parseMftPolytope(text, origin, robot);
                               });
}
}  // namespace

TEST(MftPolytope, CommittedFileMatchesTheRobotDescription) {
  const RobotDescription robot = loadRobotDescription(robotPath());
  MftPolytope p;
  ASSERT_NO_THROW(p = loadMftPolytope(polytopePath(), robot))
      << "config/mft_space.yaml is stale: regenerate with `mft-space fit --output config/mft_space.yaml`";
  EXPECT_EQ(p.robot_checksum, robot.checksum);
  EXPECT_EQ(p.fit.bad_cells_inside, 0);
  EXPECT_GE(p.fit.coverage, 0.95);
  for (int r = 0; r < kMftRows; ++r) EXPECT_NEAR(p.A.row(r).norm(), 1.0, 1e-9);
  // blkdiag: the right leg's rows act on [q4, q6] only, the left leg's on [q8, q10].
  EXPECT_EQ((p.A.topRightCorner<6, 2>().norm()), 0.0);
  EXPECT_EQ((p.A.bottomLeftCorner<6, 2>().norm()), 0.0);
  // Nominal stance of both legs is inside.
  VectorA q;
  q << -0.6435, 0.6435, -0.6435, 0.6435;
  EXPECT_TRUE(p.contains(q));
}

TEST(MftPolytope, CommittedFileIsReproducedByARefit) {
  const RobotDescription robot = loadRobotDescription(robotPath());
  const MftPolytope p = loadMftPolytope(polytopePath(), robot);
  const std::string out = ::testing::TempDir() + "/mft_space_refit_" + std::to_string(getpid()) + ".yaml";
  const auto& c = p.criteria;
  std::string cmd = std::string(MFT_BIN_DIR) + "/mft-space fit --quiet --robot " + robotPath() + " --output " + out +
                    " --joint-step " + fmt(p.fit.joint_step_rad) + " --cart-step " + fmt(p.fit.cartesian_step_m) +
                    " --edges " + std::to_string(p.fit.edges) + " --starts " + std::to_string(p.fit.starts) +
                    " --seed " + std::to_string(p.fit.rng_seed) + " --lti-min " + fmt(c.lti.lo) + " --lti-max " +
                    fmt(c.lti.hi) + " --raci-min " + fmt(c.raci.lo) + " --raci-max " + fmt(c.raci.hi) + " --accel " +
                    fmt(c.raci_options.accel_max_mps2) + " --raci-form " + raciFormName(c.raci_options.form) +
                    " --drive-k " + fmt(c.raci_options.drive_k) + (c.raci_options.gravity ? " --gravity" : "") +
                    " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const MftPolytope q = loadMftPolytope(out, robot);
  EXPECT_LT((q.A - p.A).cwiseAbs().maxCoeff(), 1e-6) << "A differs from a fresh fit: regenerate config/mft_space.yaml";
  EXPECT_LT((q.b - p.b).cwiseAbs().maxCoeff(), 1e-6) << "b differs from a fresh fit: regenerate config/mft_space.yaml";
  EXPECT_EQ(q.fit.preferable_cells, p.fit.preferable_cells);
  EXPECT_NEAR(q.fit.coverage, p.fit.coverage, 1e-9);
}

TEST(MftPolytope, RefusesAPolytopeOfAnotherRobot) {
  std::string text = readTextFile(robotPath());
  text = std::regex_replace(text, std::regex("mass_kg: 1.15"), "mass_kg: 1.25");
  const RobotDescription other = parseRobotDescription(text, "heavier-robot.yaml");
  try {
    loadMftPolytope(polytopePath(), other);
    FAIL() << "a stale polytope was accepted";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("checksum"), std::string::npos) << msg;
    EXPECT_NE(msg.find("stale"), std::string::npos) << msg;
    EXPECT_NE(msg.find("heavier-robot.yaml"), std::string::npos) << msg;
  }
}

TEST(MftPolytope, StrictLoaderRefusesBadFiles) {
  expectError("schema_version: 1", "schema_version: 2", "schema_version");
  expectError("rng_seed:", "rng_sead:", "missing key");
  expectError("schema_version: 1", "schema_version: 1\nextra_key: 3", "unknown key extra_key");
  expectError("checksum: \"[0-9a-f]+\"", "checksum: \"12xz\"", "16 hex digits");
  expectError("edges: 6", "edges: 8", "hexagon");
  expectError("bad_cells_inside: 0", "bad_cells_inside: 3", "not a conservative");
  expectError("raci_form: optimal", "raci_form: best", "optimal' or 'fixed");
  expectError("\n  b: \\[", "\n  b: [1, ", "expected 6 numbers");
  expectError("lti: \\[0.7, 1\\]", "lti: [0.9, 0.7]", "lower <= upper");
}

TEST(MftPolytope, WriteThenLoadRoundTrips) {
  const RobotDescription robot = loadRobotDescription(robotPath());
  const MftPolytope p = loadMftPolytope(polytopePath(), robot);
  std::ostringstream out;
  writeMftPolytope(out, p, {"round trip"});
  const MftPolytope q = parseMftPolytope(out.str(), "round-trip.yaml", robot);
  EXPECT_EQ((q.A - p.A).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((q.b - p.b).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(q.leg.vertices.size(), p.leg.vertices.size());
  EXPECT_EQ(q.criteria.raci.hi, p.criteria.raci.hi);
}

TEST(MftPolytope, AugmentedRowsThatDisagreeWithTheLegPolygonAreRefused) {
  const RobotDescription robot = loadRobotDescription(robotPath());
  MftPolytope p = loadMftPolytope(polytopePath(), robot);
  std::ostringstream out;
  writeMftPolytope(out, p, {});
  std::string text = out.str();
  // Change the first number of augmented.b.
  const auto pos = text.find("\n  b: [", text.find("augmented:"));
  ASSERT_NE(pos, std::string::npos);
  text.insert(pos + 7, "0.5 + ");
  text = std::regex_replace(text, std::regex("\\[0\\.5 \\+ ([-0-9.e]+)"), "[9.99");
  EXPECT_THROW(parseMftPolytope(text, "x.yaml", robot), ConfigError);
}

TEST(MftPolytope, ViolationIsTheLargestRowOfAqMinusB) {
  // Independent of the Eigen expression: each row written out as a dot product.
  const RobotDescription robot = loadRobotDescription(robotPath());
  const MftPolytope p = loadMftPolytope(polytopePath(), robot);
  std::srand(7);
  int inside = 0;
  for (int k = 0; k < 200; ++k) {
    const VectorA q = VectorA(-0.6435, 0.6435, -0.6435, 0.6435) + 0.6 * VectorA::Random();
    double worst = -1e300;
    for (int r = 0; r < kMftRows; ++r) {
      double row = -p.b[r];
      for (int c = 0; c < kNa; ++c) row += p.A(r, c) * q[c];
      worst = std::max(worst, row);
    }
    EXPECT_NEAR(polytopeViolation(p.A, p.b, q), worst, 1e-12);
    EXPECT_EQ(p.contains(q), worst <= 0.0);
    inside += worst <= 0.0;
  }
  EXPECT_GT(inside, 10);   // the sample straddles the boundary: both answers occur
  EXPECT_LT(inside, 190);
}

TEST(MftPolytope, LegViolationIsTheLegsRowsAndTheAugmentedIsTheWorseLeg) {
  // Each leg's violation from its own polygon, the augmented (10) split into its legs' rows, and their maximum:
  // the three forms the tools use must agree with the row-by-row value.
  const RobotDescription robot = loadRobotDescription(robotPath());
  const MftPolytope p = loadMftPolytope(polytopePath(), robot);
  std::srand(11);
  for (int k = 0; k < 200; ++k) {
    const VectorA q = VectorA(-0.6435, 0.6435, -0.6435, 0.6435) + 0.6 * VectorA::Random();
    double by_hand[2] = {-1e300, -1e300};
    for (int leg = 0; leg < 2; ++leg)
      for (int r = 0; r < kMftLegEdges; ++r)
        by_hand[leg] = std::max(by_hand[leg], p.leg.A(r, 0) * q[2 * leg] + p.leg.A(r, 1) * q[2 * leg + 1] - p.leg.b[r]);
    for (int leg = 0; leg < 2; ++leg) {
      EXPECT_NEAR(p.legViolation(leg, q), by_hand[leg], 1e-12);
      EXPECT_NEAR(p.leg.violation(q[2 * leg], q[2 * leg + 1]), by_hand[leg], 1e-12);
    }
    EXPECT_NEAR(p.violation(q), std::max(by_hand[0], by_hand[1]), 1e-12);
  }
}

TEST(MftPolytope, ViolationOfASquareInClosedForm) {
  // |q_rear| <= 1, |q_fore| <= 1 as four unit rows: the violation is max(|q_rear|, |q_fore|) - 1.
  HalfPlanePolygon square;
  square.angle = {0.0, M_PI / 2, M_PI, 3 * M_PI / 2};
  square.offset = {1.0, 1.0, 1.0, 1.0};
  const MftLegPolygon leg = MftLegPolygon::fromHalfPlanes(square);
  for (const auto& [qr, qf] : std::vector<std::pair<double, double>>{{0, 0}, {0.5, -0.25}, {1.5, 0.2}, {-0.3, -2.0}, {1, 1}})
    EXPECT_NEAR(leg.violation(qr, qf), std::max(std::abs(qr), std::abs(qf)) - 1.0, 1e-12) << qr << "," << qf;
  EXPECT_TRUE(leg.contains(1.0, -1.0));
  EXPECT_FALSE(leg.contains(1.01, 0.0));
}
