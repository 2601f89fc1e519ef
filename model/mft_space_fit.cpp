#include "model/mft_space_fit.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace mft::model {

namespace {
// %g, or fixed with `decimals` digits.
std::string num(double v, int decimals = -1) {
  char buf[40];
  if (decimals < 0) std::snprintf(buf, sizeof buf, "%g", v);
  else std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void stage(const MftSpaceProgress& p, const std::string& what) {
  if (p.stage) p.stage(what);
}

// A loop's (done, total) callback that reports as `what`, or none.
std::function<void(int, int)> loop(const MftSpaceProgress& p, const std::string& what) {
  if (!p.percent) return {};
  return [&p, what](int done, int total) { p.percent(what, done, total); };
}
}  // namespace

void gridMftSpaces(const RobotDescription& robot, const MftCriteria& c, double joint_step, double cart_step,
                   const MftSpaceProgress& progress, LabelGrid* joint, LabelGrid* cartesian) {
  const MftLegModel leg = MftLegModel::from(robot);
  stage(progress, "gridding actuated joint space, step " + num(joint_step) + " rad");
  *joint = gridJointSpace(leg, c, joint_step, loop(progress, "joint grid"));
  stage(progress, "gridding Cartesian foot space, step " + num(cart_step) + " m");
  *cartesian = gridCartesianSpace(leg, c, cart_step, loop(progress, "Cartesian grid"));
}

MftSpaceResult fitMftSpace(const RobotDescription& robot, const MftSpaceSettings& s, const MftSpaceProgress& progress) {
  MftSpaceResult r;
  const auto t0 = std::chrono::steady_clock::now();
  gridMftSpaces(robot, s.criteria, s.joint_step_rad, s.cartesian_step_m, progress, &r.joint, &r.cartesian);
  const auto t1 = std::chrono::steady_clock::now();
  r.grid_seconds = std::chrono::duration<double>(t1 - t0).count();

  const MftLegModel leg = MftLegModel::from(robot);
  PolygonFitOptions o;
  o.edges = s.edges;
  o.starts = s.starts;
  o.rng_seed = s.rng_seed;
  // Grow the polygon around the nominal stance (foot 0.40 m below the hip) when it is preferable.
  const LegEvaluation nominal = evaluateVerticalStance(leg, s.criteria, 0.40);
  if (nominal.preferable) {
    o.has_seed_point = true;
    o.seed_point = {nominal.pose.q_rear, nominal.pose.q_fore};
  }
  o.progress = loop(progress, "polygon fit (random starts)");
  const FitCells cells = fitCellsFromGrid(r.joint);
  stage(progress, "fitting a " + std::to_string(s.edges) + "-edge polygon to " + std::to_string(cells.good.size()) +
                  " preferable cells (" + std::to_string(cells.bad.size()) + " boundary cells)");
  r.fit = fitConservativePolygon(cells, o);
  if (!r.fit.ok) throw std::runtime_error("polygon fit failed: " + r.fit.error);
  r.quality = assessPolygon(r.joint, r.fit.polygon);
  r.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();

  MftPolytope& p = r.polytope;
  p.leg = MftLegPolygon::fromHalfPlanes(r.fit.polygon);
  p.criteria = s.criteria;
  p.robot_name = robot.name;
  p.robot_checksum = robot.checksum;
  static_cast<MftFitSettings&>(p.fit) = s;
  p.fit.area_rad2 = r.fit.area;
  p.fit.coverage = r.quality.coverage;
  p.fit.r_max_rad = r.quality.r_max;
  p.fit.bad_cells_inside = r.quality.bad_inside;
  p.fit.preferable_cells = r.joint.count(kCellPreferable);
  p.fit.reachable_cells = r.joint.countAtLeast(kCellReachable);
  r.has_augmented = s.edges == kMftLegEdges;
  if (r.has_augmented) buildAugmented(p.leg, &p);
  stage(progress, "fit done: area " + num(r.fit.area, 4) + " rad^2, coverage " +
                  num(100.0 * r.quality.coverage, 2) + " %, " + std::to_string(r.quality.bad_inside) +
                  " bad cells inside, r " + num(r.quality.r_max, 5) + " rad");
  return r;
}

}  // namespace mft::model
