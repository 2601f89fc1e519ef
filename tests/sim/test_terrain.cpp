// Terrain: the collision geometry sits where the terrain file says (ray casts), and a standing robot's feet
// rest at the expected height on every segment type.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_test_support.hpp"

using namespace mft::sim;

TEST(SimTerrain, RaysHitTheLoweredSolidsAtTheNominalHeight) {
  const Terrain t = test::terrainFile("course.yaml");
  Simulator sim(test::robot(), test::options(), t);
  const double r = sim.options().foot_collision_radius_m;
  double worst = 0.0;
  for (double x = -0.5; x < 9.0; x += 0.0137) {
    bool edge = false;  // skip the vertical faces and kinks where a ray has two answers
    for (const auto& s : t.segments) edge = edge || std::abs(x - s.x0) < 1e-3 || std::abs(x - s.x1()) < 1e-3;
    if (edge) continue;
    double offset = r;
    for (const auto& s : t.segments)
      if (s.type == SegmentType::Slope && x > s.x0 && x < s.x1()) offset = r / std::cos(s.angle_rad);
    const double err = sim.rayTerrain(x) + offset - t.heightAt(x);
    worst = std::max(worst, std::abs(err));
    EXPECT_NEAR(err, 0.0, 1e-9) << "x = " << x;
  }
  std::cout << "ray vs analytic terrain height: max error " << worst << " m\n";
}

TEST(SimTerrain, FootSphereRestsOnTheNominalHeight) {
  const Terrain t = test::terrainFile("course.yaml");
  Simulator sim(test::robot(), test::options(), t);
  for (double x : {0.3, 1.3, 2.2, 3.6, 5.2}) EXPECT_NEAR(sim.footRestHeight(x), t.heightAt(x), 1e-9) << "x = " << x;
  // Rough ground: the sphere's rounding lifts it by at most r (1/cos(slope) - 1) on the bumps' flanks.
  double worst = 0.0;
  for (double x = 6.0; x < 7.4; x += 0.0071) worst = std::max(worst, std::abs(sim.footRestHeight(x) - t.heightAt(x)));
  std::cout << "rough ground: foot rest height vs linear terrain, max " << worst << " m\n";
  EXPECT_LT(worst, 1e-3);
}

TEST(SimTerrain, StandingFeetRestAtTheExpectedHeight) {
  const Terrain t = test::terrainFile("course.yaml");
  auto o = test::options();
  Simulator sim(test::robot(), o, t);
  const double sink = 0.5 * sim.robot().totalMass() * sim.robot().gravity_mps2 / sim.robot().contact_stiffness_Npm;
  struct Case { const char* name; double x; double tol; };
  for (const Case& c : {Case{"flat", 0.0, 1e-3}, Case{"board", 1.3, 1e-3}, Case{"slope", 3.6, 1e-3}, Case{"rough", 6.7, 2e-3}}) {
    StandingPose pose;
    pose.base_x_m = c.x;
    pose.foot_offset_x_m = {0.10, -0.10};  // a wide stance: the joint-space PD alone slowly topples on the slope
    sim.reset(pose);
    test::StanceController ctrl(sim.robot(), sim.groundTruth().q);
    for (int k = 0; k < 1500; ++k) {
      sim.setCommand(ctrl.command(sim.sensors()));
      sim.step();
    }
    for (int leg = 0; leg < 2; ++leg) {
      const Eigen::Vector2d a = sim.anklePosition(leg);
      const double err = a.y() - (sim.footRestHeight(a.x()) - sink);
      std::cout << c.name << " leg " << leg << ": ankle at x " << a.x() << ", z " << a.y() << ", terrain "
                << t.heightAt(a.x()) << ", error vs rest height - sink " << err << " m\n";
      EXPECT_NEAR(err, 0.0, c.tol) << c.name;
      EXPECT_NEAR(a.y(), t.heightAt(a.x()) - sink, c.tol) << c.name;
      EXPECT_TRUE(sim.sensors().contact[static_cast<std::size_t>(leg)]) << c.name;
    }
    EXPECT_LT(std::abs(sim.groundTruth().q[2]), 0.05) << c.name;
    EXPECT_EQ(sim.stats().body_contact_steps, 0u) << c.name;
  }
}
