// The offline pipeline as a library call (model/mft_space_fit.hpp): with the settings config/mft_space.yaml
// records, model::fitMftSpace gives the committed A and b again, and reports its stages and loops in order.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "model/mft_space_fit.hpp"

using namespace mft::model;

namespace {
std::string configFile(const char* name) { return std::string(MFT_CONFIG_DIR) + "/" + name; }

MftSpaceSettings settingsOf(const MftPolytope& p) {
  MftSpaceSettings s;
  static_cast<MftFitSettings&>(s) = p.fit;
  s.criteria = p.criteria;
  return s;
}
}  // namespace

TEST(MftSpaceFit, ReproducesTheCommittedPolytopeAndReportsItsStages) {
  const RobotDescription robot = loadRobotDescription(configFile("robot.yaml"));
  const MftPolytope committed = loadMftPolytope(configFile("mft_space.yaml"), robot);
  std::vector<std::string> stages, finished_loops;
  MftSpaceProgress progress;
  progress.stage = [&](const std::string& what) { stages.push_back(what); };
  progress.percent = [&](const std::string& what, int done, int total) {
    EXPECT_LE(done, total) << what;
    if (done == total) finished_loops.push_back(what);
  };
  const MftSpaceResult r = fitMftSpace(robot, settingsOf(committed), progress);

  ASSERT_TRUE(r.has_augmented);
  EXPECT_LT((r.polytope.A - committed.A).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((r.polytope.b - committed.b).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(r.polytope.fit.preferable_cells, committed.fit.preferable_cells);
  EXPECT_EQ(r.polytope.fit.bad_cells_inside, 0);
  EXPECT_NEAR(r.polytope.fit.coverage, committed.fit.coverage, 1e-9);
  EXPECT_EQ(r.polytope.robot_checksum, robot.checksum);

  ASSERT_EQ(stages.size(), 4u);
  EXPECT_EQ(stages[0].rfind("gridding actuated joint space", 0), 0u) << stages[0];
  EXPECT_EQ(stages[1].rfind("gridding Cartesian foot space", 0), 0u) << stages[1];
  EXPECT_EQ(stages[2].rfind("fitting a 6-edge polygon", 0), 0u) << stages[2];
  EXPECT_EQ(stages[3].rfind("fit done: area", 0), 0u) << stages[3];
  EXPECT_EQ(finished_loops, (std::vector<std::string>{"joint grid", "Cartesian grid", "polygon fit (random starts)"}));
}

TEST(MftSpaceFit, RunsWithoutProgressAndKeepsNonHexagonsOutOfTheAugmentedPolytope) {
  const RobotDescription robot = loadRobotDescription(configFile("robot.yaml"));
  MftSpaceSettings s;
  s.criteria = MftCriteria::defaults(robot);
  s.joint_step_rad = 0.05;
  s.cartesian_step_m = 0.05;
  s.edges = 5;
  s.starts = 2;
  const MftSpaceResult r = fitMftSpace(robot, s);
  EXPECT_FALSE(r.has_augmented);
  EXPECT_EQ(r.fit.polygon.size(), 5);
  EXPECT_EQ(r.polytope.A.norm(), 0.0);  // a pentagon has no 12 x 4 augmented form
  EXPECT_GT(r.polytope.fit.preferable_cells, 0);
}
