// Blind walking over the paper's course (config/terrain/course.yaml) in process, MFT-WBC, Kalman estimator, the
// command of `mft-experiment terrain` (0.42 m, 0.25 m/s). What is measured and why (docs/results/terrain.md):
// - the 3 cm board's leading edge stops the robot whenever the blind footfall before it lands within about
//   3 cm of the edge (that leg's fore shank touches the edge), for the paper's setup and every profile set
//   tried, at most speeds: a matter of the gait's phase at x = 1.0 m and the leg's geometry, not of the
//   controller. The last test pins that cause on the whole course; the others walk the course with the board
//   replaced by level ground (built from the course file, everything else as is);
// - on the 6 degree up-slope the paper's k_v = 0.16 stalls (a growing two-step oscillation of the foot placement)
//   and the robot falls back down, while the profile kv-0.145 (k_v = 1/sigma1 of the LIP orbit) climbs it and
//   crosses the rough ground: the minimal profile the course needs, asserted both ways below.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "chain/closed_loop.hpp"
#include "chain/scenario.hpp"
#include "model/coordinates.hpp"
#include "model/five_bar.hpp"
#include "sim/simulator.hpp"
#include "sim/terrain.hpp"

namespace mft::closedloop {
namespace {

constexpr double kHeight = 0.42, kSpeed = 0.25, kDuration = 60.0;

sim::Terrain courseWithoutBoard() {
  sim::Terrain t = sim::loadTerrain(std::string(MFT_CONFIG_DIR) + "/terrain/course.yaml");
  int boards = 0;
  for (sim::TerrainSegment& s : t.segments) {
    if (s.type != sim::SegmentType::Board) continue;
    ++boards;
    s.type = sim::SegmentType::Flat;  // a board ends at the level it starts at: later segments keep x0 and z0
    s.height = 0.0;
    s.friction = -1.0;
  }
  EXPECT_EQ(boards, 1) << "course.yaml changed: this test removes its one board";
  return t;
}

const sim::TerrainSegment& segmentOf(const sim::Terrain& t, sim::SegmentType type) {
  const auto it = std::find_if(t.segments.begin(), t.segments.end(), [&](const auto& s) { return s.type == type; });
  if (it == t.segments.end()) throw std::runtime_error("course.yaml has no such segment");
  return *it;
}

// The course's command as mft-experiment terrain gives it: stand 1 s, step in place 1 s, then walk.
chain::Scenario courseScenario() {
  chain::Scenario s = makeScenario(kHeight, 0.0, kDuration, "mft", "kalman", 1.0);
  s.commands.push_back({2.0, chain::LocomotionMode::Walk, kHeight, kSpeed});
  return s;
}

struct CourseRun {
  RunSummary summary;
  double max_x = 0.0;
  double reached_at_s = -1.0;  // first time the base passed `goal_x`; < 0: never
};

CourseRun walk(const std::vector<std::string>& profiles, const sim::Terrain& terrain, double goal_x) {
  const Configs c = loadConfigs(MFT_CONFIG_DIR, profiles);
  RunOptions o;
  o.stats_from_s = 5.0;
  o.terrain = terrain;
  ClosedLoop loop(c, courseScenario(), o);
  CourseRun r;
  r.summary = loop.run([&](const ClosedLoop& l) {
    const double x = l.truthAtEstimate().q[0];
    r.max_x = std::max(r.max_x, x);
    if (r.reached_at_s < 0.0 && x >= goal_x) r.reached_at_s = l.truthAtEstimate().time_s;
  });
  std::printf("%s\nmax x %.3f m, past %.2f m at %.2f s\n", r.summary.toJson().c_str(), r.max_x, goal_x, r.reached_at_s);
  return r;
}

// kv-0.145: up the slope, over the rough ground, past its end + 0.3 m (the experiment's "traversed") in 60 s.
// Measured: past 7.9 m at 44.4 s, no fall (0.20-0.28 m/s all traverse in 60 s).
TEST(TerrainCourseWithoutBoard, Kv0145ClimbsTheSlopeAndCrossesTheRoughGround) {
  const sim::Terrain t = courseWithoutBoard();
  const double goal = segmentOf(t, sim::SegmentType::Rough).x1() + 0.3;
  const CourseRun r = walk({"kv-0.145"}, t, goal);
  ASSERT_FALSE(r.summary.fell) << r.summary.fall_reason << " at " << r.summary.fall_time_s << " s, max x " << r.max_x;
  EXPECT_GE(r.reached_at_s, 0.0) << "the base only got to x = " << r.max_x << " m in " << kDuration << " s";
  EXPECT_EQ(r.summary.non_optimal_solves, 0u);
}

// The paper's setup (no profile) never gets to the top of the slope: the reason the course needs kv-0.145.
// Measured: stalls at the slope's foot (x 2.6 m) and falls there (0.20, 0.25, 0.30 m/s). If this starts to
// fail, the default climbs: update docs/results/terrain.md and drop the profile from the terrain experiment.
TEST(TerrainCourseWithoutBoard, PaperSetupStallsOnTheUpSlope) {
  const sim::Terrain t = courseWithoutBoard();
  const sim::TerrainSegment& slope = segmentOf(t, sim::SegmentType::Slope);
  const CourseRun r = walk({}, t, slope.x1());
  EXPECT_GT(r.max_x, slope.x0) << "did not even reach the slope";
  EXPECT_LT(r.reached_at_s, 0.0) << "the paper's setup reached the top of the slope (x " << slope.x1() << " m) at "
                                 << r.reached_at_s << " s";
}

// The whole course (board included), the command of `mft-experiment terrain` with kv-0.145: the blind walk ends at
// the board's leading edge, and the cause is pinned down here (docs/results/terrain.md#under-the-papers-setup-what-stops-it
// what-stops-it). The first terrain contact of a non-foot body is a FORE shank's capsule on the board's leading
// corner (x = 1.0 m, top 3 cm minus the 5 mm foot sphere the solids are lowered by), while that leg's ankle is
// still on the floor side of the edge, 0-3 cm before it: the fore shank leans 20-26 degrees forward from the
// ankle, and its capsule (12 mm radius, from 27 mm above the ankle) reaches about 2 cm ahead of the ankle at the
// board's height. Measured: 6.24 s, right fore shank at (1.000, 0.025) m, ankle (0.986, 0.012) m, descending.
// If this starts to fail, the course may be passable: make it a traversal test and update the docs.
TEST(TerrainCourse, BoardLeadingEdgeMeetsAForeShankBeforeTheFoot) {
  const Configs c = loadConfigs(MFT_CONFIG_DIR, {"kv-0.145"});
  const sim::Terrain terrain = sim::loadTerrain(std::string(MFT_CONFIG_DIR) + "/terrain/course.yaml");
  const sim::TerrainSegment& board = segmentOf(terrain, sim::SegmentType::Board);
  RunOptions o;
  o.stats_from_s = 5.0;
  o.terrain = terrain;
  ClosedLoop loop(c, courseScenario(), o);
  model::VectorQ q_at_contact = model::VectorQ::Zero();
  bool have_q = false;
  const RunSummary& r = loop.run([&](const ClosedLoop& l) {
    if (!have_q && l.simulator().stats().first_body_contact.seen) {
      q_at_contact = l.simulator().groundTruth().q;
      have_q = true;
    }
  });
  std::printf("%s\n", r.toJson().c_str());
  ASSERT_TRUE(r.fell) << "the course was walked past the board: make this a traversal test";
  EXPECT_EQ(r.fall_reason, "a non-foot body touched the ground");
  ASSERT_TRUE(r.first_body_contact.seen);
  ASSERT_TRUE(have_q);
  const sim::BodyContact& b = r.first_body_contact;
  const std::string body = sim::robotBodyName(b.body);
  EXPECT_NE(body.find("fore shank"), std::string::npos) << body;
  const double foot_r = c.sim.foot_collision_radius_m;
  EXPECT_NEAR(b.point.x(), board.x0, 0.005) << "not at the board's leading edge";
  EXPECT_NEAR(b.point.y(), board.z0 + board.height - foot_r, 0.005) << "not at the height of the board's top";
  EXPECT_LE(b.time_s, r.fall_time_s);
  // That leg's ankle (rear chain's tip, model kinematics) when the shank touched: in front of the edge, on the
  // floor side, lower than the board's top.
  const int leg = (b.body - 1) / 4;
  const double pitch = q_at_contact[model::kBasePitch];
  const double a_thigh = pitch + q_at_contact[model::hipRearIndex(leg)];
  const double a_shank = a_thigh + q_at_contact[model::kneeRearIndex(leg)];
  const Eigen::Vector2d ankle = Eigen::Vector2d(q_at_contact[model::kBaseX], q_at_contact[model::kBaseZ]) +
                                c.robot.thigh.length_m * model::linkDirection(a_thigh) +
                                c.robot.shank.length_m * model::linkDirection(a_shank);
  std::printf("%s at (%.4f, %.4f) m, t %.3f s; its ankle at (%.4f, %.4f) m\n", body.c_str(), b.point.x(),
              b.point.y(), b.time_s, ankle.x(), ankle.y());
  EXPECT_GT(ankle.x(), board.x0 - 0.03);
  EXPECT_LT(ankle.x(), board.x0);
  EXPECT_LT(ankle.y(), board.z0 + board.height);
}

}  // namespace
}  // namespace mft::closedloop
