// Paper (18): the base height and pitch references, z_ref = z_cmd and theta_ref = 0, with the project's rate
// limit on z_ref. Checked against closed forms: the step of one tick, and a whole ramp summed tick by tick.
#include <gtest/gtest.h>

#include <cmath>

#include "planner/base_reference.hpp"

namespace mft::planner {
namespace {

TEST(HeightPitchReference, FarFromTheCommandItMovesAtTheRateLimit) {
  for (double dt : {0.001, 0.002, 0.01}) {
    const HeightPitchReference up = heightPitchReference(0.40, 0.44, 0.1, dt);
    EXPECT_NEAR(up.base_z[0], 0.40 + 0.1 * dt, 1e-15);
    EXPECT_NEAR(up.base_z[1], 0.1, 1e-12);
    EXPECT_EQ(up.base_z[2], 0.0);
    const HeightPitchReference down = heightPitchReference(0.44, 0.40, 0.1, dt);
    EXPECT_NEAR(down.base_z[0], 0.44 - 0.1 * dt, 1e-15);
    EXPECT_NEAR(down.base_z[1], -0.1, 1e-12);
    EXPECT_EQ(up.base_pitch.norm(), 0.0);  // theta_ref = 0, no pitch rate or acceleration
    EXPECT_EQ(down.base_pitch.norm(), 0.0);
  }
}

TEST(HeightPitchReference, WithinOneStepItIsTheCommand) {
  // 0.00005 m away at 0.1 m/s and 1 ms (0.0001 m a tick): z_ref = z_cmd, the velocity is the step over dt.
  const HeightPitchReference r = heightPitchReference(0.42, 0.42005, 0.1, 0.001);
  EXPECT_EQ(r.base_z[0], 0.42005);
  EXPECT_NEAR(r.base_z[1], 0.05, 1e-9);
  const HeightPitchReference held = heightPitchReference(0.42, 0.42, 0.1, 0.001);
  EXPECT_EQ(held.base_z[0], 0.42);
  EXPECT_EQ(held.base_z[1], 0.0);
  // No time passed: nothing moves, and the velocity is 0, not NaN.
  const HeightPitchReference still = heightPitchReference(0.40, 0.44, 0.1, 0.0);
  EXPECT_EQ(still.base_z[0], 0.40);
  EXPECT_EQ(still.base_z[1], 0.0);
}

TEST(HeightPitchReference, ARampReachesTheCommandInDistanceOverRate) {
  // 0.40 -> 0.43 at 0.1 m/s, 1 ms ticks: 0.3 s = 300 ticks; the velocities summed times dt give the distance.
  double z = 0.40, travelled = 0.0;
  int ticks_moving = 0;
  for (int k = 0; k < 1000; ++k) {
    const HeightPitchReference r = heightPitchReference(z, 0.43, 0.1, 0.001);
    travelled += r.base_z[1] * 0.001;
    if (r.base_z[0] != z) ++ticks_moving;
    z = r.base_z[0];
    EXPECT_LE(std::abs(r.base_z[1]), 0.1 + 1e-12);
  }
  EXPECT_NEAR(z, 0.43, 1e-12);
  EXPECT_NEAR(travelled, 0.03, 1e-12);
  EXPECT_NEAR(ticks_moving, 300, 1);  // the last step may be a rounding remainder
}

}  // namespace
}  // namespace mft::planner
