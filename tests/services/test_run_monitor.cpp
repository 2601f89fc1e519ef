// Fall criteria and tracking statistics of a run.
#include <gtest/gtest.h>

#include "chain/run_monitor.hpp"

using namespace mft;

namespace {
model::GroundTruthState standing(double t, double z, double pitch) {
  model::GroundTruthState s;
  s.time_s = t;
  s.q[1] = z;
  s.q[2] = pitch;
  s.lti = {0.8, 0.8};
  return s;
}
}  // namespace

TEST(RunMonitor, StatisticsStartAfterSettling) {
  chain::RunMonitor m({}, 1.0);
  EXPECT_FALSE(m.update(standing(0.5, 0.30, 0.0), 0.42, 0));  // before settling: not counted
  EXPECT_FALSE(m.update(standing(1.5, 0.43, 0.02), 0.42, 0));
  EXPECT_FALSE(m.update(standing(1.6, 0.41, -0.02), 0.42, 0));
  EXPECT_EQ(m.heightError().n, 2u);
  EXPECT_NEAR(m.heightError().rms(), 0.01, 1e-12);
  EXPECT_NEAR(m.pitchError().max_abs, 0.02, 1e-12);
  EXPECT_FALSE(m.fell());
}

TEST(RunMonitor, EachFallCriterion) {
  chain::FallCriteria c;
  {
    chain::RunMonitor m(c, 0);
    EXPECT_TRUE(m.update(standing(2.0, 0.2, 0), 0.42, 0));
    EXPECT_NE(m.fallReason().find("base below"), std::string::npos);
    EXPECT_DOUBLE_EQ(m.fallTime(), 2.0);
    EXPECT_FALSE(m.update(standing(2.1, 0.1, 0), 0.42, 0));  // reported once
  }
  {
    chain::RunMonitor m(c, 0);
    EXPECT_TRUE(m.update(standing(1.0, 0.42, -0.9), 0.42, 0));
    EXPECT_NE(m.fallReason().find("pitch"), std::string::npos);
  }
  {
    chain::RunMonitor m(c, 0);
    EXPECT_TRUE(m.update(standing(1.0, 0.42, 0), 0.42, 3));
    EXPECT_NE(m.fallReason().find("non-foot body"), std::string::npos);
  }
  {
    chain::RunMonitor m(c, 0);
    auto s = standing(1.0, 0.42, 0);
    s.lti = {0.8, 0.01};
    EXPECT_TRUE(m.update(s, 0.42, 0));
    EXPECT_NE(m.fallReason().find("singular"), std::string::npos);
  }
}

TEST(RunMonitor, AverageSpeed) {
  chain::RunMonitor m({}, 0);
  auto s = standing(0.0, 0.42, 0);
  m.update(s, 0.42, 0);
  s.time_s = 10.0;
  s.q[0] = 3.0;
  m.update(s, 0.42, 0);
  EXPECT_NEAR(m.averageSpeed(), 0.3, 1e-12);
}
