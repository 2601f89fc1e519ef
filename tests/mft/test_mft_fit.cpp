// The conservative polygon fit (docs/reference/five-bar-theory.md#the-polygon-fit): conditions 1 and 2 on the default robot, the numbers of
// section 3.4, the vertical stance inside/outside, and synthetic shapes with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "model/mft_polygon_fit.hpp"

using namespace mft::model;

namespace {
RobotDescription robot() { return loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml"); }

struct Fit {
  LabelGrid grid;
  PolygonFitResult fit;
  PolygonQuality quality;
};
Fit fitDefault(double step) {
  const RobotDescription d = robot();
  const MftLegModel leg = MftLegModel::from(d);
  const MftCriteria c = MftCriteria::defaults(d);
  Fit f;
  f.grid = gridJointSpace(leg, c, step);
  PolygonFitOptions o;
  const LegEvaluation nominal = evaluateVerticalStance(leg, c, 0.40);
  o.has_seed_point = true;
  o.seed_point = {nominal.pose.q_rear, nominal.pose.q_fore};
  f.fit = fitConservativePolygon(fitCellsFromGrid(f.grid), o);
  f.quality = assessPolygon(f.grid, f.fit.polygon);
  return f;
}

// No point of any bad cell box lies in the polygon: check a 5 x 5 sample of every bad box.
int badBoxesTouched(const LabelGrid& g, const HalfPlanePolygon& p) {
  int touched = 0;
  for (int j = -1; j <= g.y.n; ++j)
    for (int i = -1; i <= g.x.n; ++i) {
      const bool inside_grid = i >= 0 && j >= 0 && i < g.x.n && j < g.y.n;
      if (inside_grid && g.at(i, j) == kCellPreferable) continue;
      bool hit = false;
      for (int a = 0; a < 5 && !hit; ++a)
        for (int b = 0; b < 5 && !hit; ++b)
          hit = p.contains(g.node(i, j) + Eigen::Vector2d((a / 4.0 - 0.5) * g.x.step, (b / 4.0 - 0.5) * g.y.step));
      touched += hit;
    }
  return touched;
}
}  // namespace

TEST(MftFit, DefaultRobotPolygonIsConservativeAndCovers95Percent) {
  const Fit f = fitDefault(0.01);
  ASSERT_TRUE(f.fit.ok) << f.fit.error;
  EXPECT_EQ(f.fit.polygon.size(), 6);
  EXPECT_EQ(f.quality.bad_inside, 0);                     // condition 1
  EXPECT_EQ(badBoxesTouched(f.grid, f.fit.polygon), 0);   // even the bad cell boxes stay outside
  EXPECT_GE(f.quality.coverage, 0.95);
  EXPECT_LT(f.quality.r_max, 0.02);  // condition 2 with r = 2 grid steps
  for (int k = 0; k < f.fit.polygon.size(); ++k) EXPECT_TRUE(std::isfinite(f.fit.polygon.offset[k]));
}

TEST(MftFit, ReproducesTheDesignNotesAtTwoHundredthsOfARadian) {
  const Fit f = fitDefault(0.02);
  EXPECT_EQ(f.grid.x.n, 113);
  EXPECT_EQ(f.grid.countAtLeast(kCellReachable), 12028);
  EXPECT_EQ(f.grid.count(kCellPreferable), 7770);
  EXPECT_NEAR(f.fit.area, 3.078, 0.01);
  EXPECT_NEAR(f.quality.coverage, 0.982, 0.005);
  EXPECT_EQ(f.quality.bad_inside, 0);
  EXPECT_LT(f.quality.r_max, 0.005);
}

TEST(MftFit, VerticalStanceInsideAt038To042AndOutsideAt044And046) {
  const Fit f = fitDefault(0.01);
  const RobotDescription d = robot();
  const MftLegModel leg = MftLegModel::from(d);
  const MftCriteria c = MftCriteria::defaults(d);
  for (double z : {0.38, 0.40, 0.42, 0.44, 0.46}) {
    const LegEvaluation e = evaluateVerticalStance(leg, c, z);
    ASSERT_EQ(e.status, FiveBarStatus::Ok);
    EXPECT_EQ(f.fit.polygon.contains({e.pose.q_rear, e.pose.q_fore}), z < 0.43) << z;
  }
}

namespace {
// An n x n grid of 0.02 cells from (lo, lo): preferable where `preferable(node)` holds, reachable elsewhere.
template <class Shape>
LabelGrid shapeGrid(double lo, int n, Shape&& preferable) {
  LabelGrid g;
  g.x = g.y = GridAxis{lo, 0.02, n};
  g.labels.resize(n * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) g.labels[j * n + i] = preferable(g.node(i, j)) ? kCellPreferable : kCellReachable;
  return g;
}

// Fits with the default options; the polygon's area lies in (area_lo, area_hi) and it holds no bad cell.
void expectConservativeFit(const LabelGrid& g, double area_lo, double area_hi) {
  const PolygonFitResult r = fitConservativePolygon(fitCellsFromGrid(g), PolygonFitOptions{});
  ASSERT_TRUE(r.ok);
  EXPECT_GT(r.area, area_lo);
  EXPECT_LT(r.area, area_hi);
  EXPECT_EQ(assessPolygon(g, r.polygon).bad_inside, 0);
  EXPECT_EQ(badBoxesTouched(g, r.polygon), 0);
}
}  // namespace

TEST(MftFit, DiscGivesTheInscribedHexagon) {
  // Unit disc on a 0.02 grid: the best conservative hexagon is close to the regular one (area 2.598 for r = 1).
  const LabelGrid g = shapeGrid(-1.2, 121, [](const Eigen::Vector2d& x) { return x.norm() <= 1.0; });
  expectConservativeFit(g, 2.5, 2.62);
}

TEST(MftFit, LShapeKeepsOneArm) {
  // An L of two 2 x 0.6 arms: no convex piece holds more than one arm (about 0.61 x 2.02 with the cell boxes).
  const LabelGrid g = shapeGrid(0.0, 101, [](const Eigen::Vector2d& x) { return x.x() <= 0.6 || x.y() <= 0.6; });
  expectConservativeFit(g, 1.2, 1.3);
}

TEST(MftFit, SameSeedSameResult) {
  const Fit a = fitDefault(0.02), b = fitDefault(0.02);
  ASSERT_EQ(a.fit.polygon.size(), b.fit.polygon.size());
  for (int k = 0; k < a.fit.polygon.size(); ++k) {
    EXPECT_EQ(a.fit.polygon.angle[k], b.fit.polygon.angle[k]);
    EXPECT_EQ(a.fit.polygon.offset[k], b.fit.polygon.offset[k]);
  }
}

TEST(MftFit, NothingToFitIsAnErrorNotACrash) {
  LabelGrid g;
  g.x = g.y = GridAxis{0.0, 0.1, 5};
  g.labels.assign(25, kCellReachable);
  const PolygonFitResult r = fitConservativePolygon(fitCellsFromGrid(g), PolygonFitOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.error.empty());
  PolygonFitOptions two;
  two.edges = 2;
  g.labels[12] = kCellPreferable;
  EXPECT_FALSE(fitConservativePolygon(fitCellsFromGrid(g), two).ok);
}
