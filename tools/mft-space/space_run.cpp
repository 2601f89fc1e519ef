#include "space_run.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "json_writer.hpp"

namespace mft::tools {

using namespace mft::model;

namespace {
// %g, or fixed with `decimals` digits.
std::string num(double v, int decimals = -1) {
  char buf[40];
  if (decimals < 0) std::snprintf(buf, sizeof buf, "%g", v);
  else std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
}  // namespace

const char* const kSpaceOptions[] = {"joint-step", "cart-step", "edges", "starts", "seed", "lti-min", "lti-max",
                                     "raci-min", "raci-max", "accel", "raci-form", "drive-k", nullptr};

MftCriteria criteriaFromArgs(const CliArgs& a, const RobotDescription& robot) {
  MftCriteria c = MftCriteria::defaults(robot);
  c.lti = {a.number("lti-min", c.lti.lo), a.number("lti-max", c.lti.hi)};
  c.raci = {a.number("raci-min", c.raci.lo), a.number("raci-max", c.raci.hi)};
  if (!(c.lti.lo <= c.lti.hi)) throw UsageError("--lti-min must not exceed --lti-max");
  if (!(c.raci.lo <= c.raci.hi)) throw UsageError("--raci-min must not exceed --raci-max");
  c.raci_options.accel_max_mps2 = a.positive("accel", c.raci_options.accel_max_mps2);
  c.raci_options.drive_k = a.positive("drive-k", c.raci_options.drive_k);
  const std::string form = a.text("raci-form", "optimal");
  if (!parseRaciForm(form, &c.raci_options.form))
    throw UsageError("--raci-form expects 'optimal' or 'fixed', got '" + form + "'");
  c.raci_options.gravity = a.flag("gravity");
  return c;
}

SpaceSettings settingsFromArgs(const CliArgs& a, const RobotDescription& robot) {
  SpaceSettings s;
  s.criteria = criteriaFromArgs(a, robot);
  s.joint_step_rad = a.positive("joint-step", s.joint_step_rad);
  s.cartesian_step_m = a.positive("cart-step", s.cartesian_step_m);
  // Keep the grids within what a run can handle in seconds (and memory).
  if (s.joint_step_rad < 1e-3 || s.joint_step_rad > 0.5) throw UsageError("--joint-step must lie in [0.001, 0.5] rad");
  if (s.cartesian_step_m < 1e-3 || s.cartesian_step_m > 0.1) throw UsageError("--cart-step must lie in [0.001, 0.1] m");
  s.edges = a.integer("edges", s.edges, 3, 32);
  s.starts = a.integer("starts", s.starts, 1, 1000);
  s.rng_seed = static_cast<unsigned>(a.integer("seed", static_cast<int>(s.rng_seed), 0, 1 << 30));
  return s;
}

void gridSpaces(const RobotDescription& robot, const MftCriteria& c, double joint_step, double cart_step,
                Progress& progress, LabelGrid* joint, LabelGrid* cartesian) {
  const MftLegModel leg = MftLegModel::from(robot);
  progress.stage("gridding actuated joint space, step " + num(joint_step) + " rad");
  *joint = gridJointSpace(leg, c, joint_step, [&](int d, int t) { progress.percent("joint grid", d, t); });
  progress.stage("gridding Cartesian foot space, step " + num(cart_step) + " m");
  *cartesian = gridCartesianSpace(leg, c, cart_step, [&](int d, int t) { progress.percent("Cartesian grid", d, t); });
}

SpaceResult runSpace(const RobotDescription& robot, const SpaceSettings& s, Progress& progress) {
  SpaceResult r;
  const auto t0 = std::chrono::steady_clock::now();
  gridSpaces(robot, s.criteria, s.joint_step_rad, s.cartesian_step_m, progress, &r.joint, &r.cartesian);
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
  o.progress = [&](int d, int t) { progress.percent("polygon fit (random starts)", d, t); };
  const FitCells cells = fitCellsFromGrid(r.joint);
  progress.stage("fitting a " + std::to_string(s.edges) + "-edge polygon to " + std::to_string(cells.good.size()) +
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
  p.fit.joint_step_rad = s.joint_step_rad;
  p.fit.cartesian_step_m = s.cartesian_step_m;
  p.fit.edges = s.edges;
  p.fit.starts = s.starts;
  p.fit.rng_seed = s.rng_seed;
  p.fit.area_rad2 = r.fit.area;
  p.fit.coverage = r.quality.coverage;
  p.fit.r_max_rad = r.quality.r_max;
  p.fit.bad_cells_inside = r.quality.bad_inside;
  p.fit.preferable_cells = r.joint.count(kCellPreferable);
  p.fit.reachable_cells = r.joint.countAtLeast(kCellReachable);
  r.has_augmented = s.edges == kMftLegEdges;
  if (r.has_augmented) buildAugmented(p.leg, &p);
  progress.stage("fit done: area " + num(r.fit.area, 4) + " rad^2, coverage " +
                 num(100.0 * r.quality.coverage, 2) + " %, " + std::to_string(r.quality.bad_inside) +
                 " bad cells inside, r " + num(r.quality.r_max, 5) + " rad");
  return r;
}

void writePolytopeFile(const std::string& path, const SpaceResult& r, const RobotDescription& robot) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  std::string base = robot.source_file;
  if (const auto slash = base.find_last_of('/'); slash != std::string::npos) base = base.substr(slash + 1);
  std::vector<std::string> header = {
      "MFT preferable space of one five-bar leg and the augmented polytope A q_a <= b of the paper (sec. III-B).",
      "Generated by mft-space from " + base + " (" + robot.name + "); do not edit by hand.",
      "Regenerate: build/release/bin/mft-space fit --output config/mft_space.yaml"};
  if (!r.has_augmented)
    header.push_back("NOTE: not a hexagon, so there is no 12x4 augmented polytope: the WBC loader refuses this file.");
  writeMftPolytope(out, r.polytope, header);
  out.close();
  if (!out) throw std::runtime_error("error while writing " + path);
}

std::string summaryJson(const SpaceResult& r) {
  const auto& q = r.quality;
  JsonWriter edges;
  edges.beginArray();
  for (int k = 0; k < r.fit.polygon.size(); ++k) {
    const Eigen::Vector2d n = r.fit.polygon.normal(k);
    edges.beginObject().key("normal").numbers({n.x(), n.y()}, kDigits);
    edges.field("offset", r.fit.polygon.offset[k], kDigits).endObject();
  }
  edges.endArray();
  JsonWriter verts;
  verts.beginArray();
  for (const auto& v : r.polytope.leg.vertices) verts.numbers({v.x(), v.y()}, kDigits);
  verts.endArray();
  return JsonWriter().beginObject()
      .field("joint_step_rad", r.polytope.fit.joint_step_rad, kDigits)
      .field("joint_nodes", static_cast<double>(r.joint.labels.size()), kDigits)
      .field("reachable_cells", r.polytope.fit.reachable_cells, kDigits)
      .field("preferable_cells", r.polytope.fit.preferable_cells, kDigits)
      .field("cartesian_step_m", r.polytope.fit.cartesian_step_m, kDigits)
      .field("cartesian_reachable_cells", r.cartesian.countAtLeast(kCellReachable), kDigits)
      .field("cartesian_preferable_cells", r.cartesian.count(kCellPreferable), kDigits)
      .field("edges", r.fit.polygon.size(), kDigits)
      .field("area_rad2", r.fit.area, kDigits)
      .field("coverage", q.coverage, kDigits)
      .field("covered_cells", q.good_inside, kDigits)
      .field("bad_cells_inside", q.bad_inside, kDigits)
      .field("r_max_rad", q.r_max, kDigits)
      .field("grid_seconds", r.grid_seconds, kDigits)
      .field("fit_seconds", r.fit_seconds, kDigits)
      .key("polygon_edges").raw(edges.str())
      .key("polygon_vertices").raw(verts.str())
      .endObject().str();
}

std::string summaryText(const SpaceResult& r) {
  const auto& q = r.quality;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "joint grid      %d x %d nodes, step %.4g rad: %d reachable, %d preferable\n"
                "Cartesian grid  %d x %d nodes, step %.4g m: %d reachable, %d preferable\n"
                "polygon         %d edges, area %.4f rad^2\n"
                "coverage        %.2f %% of preferable cells (%d of %d)\n"
                "bad cells inside %d (condition 1)\n"
                "r               %.5f rad (condition 2: every uncovered preferable cell within r)\n"
                "time            grid %.2f s, fit %.2f s\n",
                r.joint.x.n, r.joint.y.n, r.joint.x.step, r.polytope.fit.reachable_cells, r.polytope.fit.preferable_cells,
                r.cartesian.x.n, r.cartesian.y.n, r.cartesian.x.step, r.cartesian.countAtLeast(kCellReachable),
                r.cartesian.count(kCellPreferable), r.fit.polygon.size(), r.fit.area, 100.0 * q.coverage, q.good_inside,
                q.good_total, q.bad_inside, q.r_max, r.grid_seconds, r.fit_seconds);
  std::string s = buf;
  s += "edges           n' [q_rear, q_fore] <= b\n";
  for (int k = 0; k < r.fit.polygon.size(); ++k) {
    const Eigen::Vector2d n = r.fit.polygon.normal(k);
    std::snprintf(buf, sizeof buf, "                [%8.5f, %8.5f] . q <= %8.5f\n", n.x(), n.y(), r.fit.polygon.offset[k]);
    s += buf;
  }
  return s;
}

}  // namespace mft::tools
