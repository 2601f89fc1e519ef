#include "model/mft_polytope.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>

#include "common/strict_yaml.hpp"

namespace mft::model {

using config::ConfigError;
using config::StrictNode;

bool MftLegPolygon::contains(double q_rear, double q_fore, double tol) const {
  return A.rows() == 0 || violation(q_rear, q_fore) <= tol;
}

double MftLegPolygon::violation(double q_rear, double q_fore) const {
  return polytopeViolation(A, b, Eigen::Vector2d(q_rear, q_fore));
}

MftLegPolygon MftLegPolygon::fromHalfPlanes(const HalfPlanePolygon& p) {
  MftLegPolygon l;
  l.A.resize(p.size(), 2);
  l.b.resize(p.size());
  for (int k = 0; k < p.size(); ++k) {
    l.A.row(k) = p.normal(k).transpose();
    l.b[k] = p.offset[k];
  }
  l.vertices = p.vertices();
  return l;
}

void buildAugmented(const MftLegPolygon& leg, MftPolytope* p) {
  if (leg.A.rows() != kMftLegEdges)
    throw ConfigError("the augmented MFT polytope needs a hexagon per leg (" + std::to_string(kMftLegEdges) +
                      " edges), got " + std::to_string(leg.A.rows()));
  p->A.setZero();
  for (int l = 0; l < kNumLegs; ++l) {
    p->A.block<kMftLegEdges, 2>(l * kMftLegEdges, 2 * l) = leg.A;
    p->b.segment<kMftLegEdges>(l * kMftLegEdges) = leg.b;
  }
}

namespace {

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}
std::string list(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + fmt(v[i]);
  return s + "]";
}
template <typename M>
std::string rowList(const M& m, int r) {
  std::vector<double> v(m.cols());
  for (int c = 0; c < m.cols(); ++c) v[c] = m(r, c);
  return list(v.data(), static_cast<int>(v.size()));
}

// Row k of a flat row-major list.
Eigen::RowVectorXd flatRow(const std::vector<double>& v, int k, int cols) {
  Eigen::RowVectorXd r(cols);
  for (int c = 0; c < cols; ++c) r[c] = v[static_cast<std::size_t>(k) * cols + c];
  return r;
}

MftPolytope read(StrictNode& root, const RobotDescription& robot) {
  root.useSchema("mft_space");  // every number it reads is checked against its range (config_schema.hpp)
  MftPolytope p;

  auto& rob = root.child("robot");
  p.robot_name = rob.text("name");
  const std::string hex = rob.text("checksum");
  char* end = nullptr;
  p.robot_checksum = std::strtoull(hex.c_str(), &end, 16);
  if (hex.size() != 16 || *end != '\0') rob.fail("checksum", "expected 16 hex digits, got '" + hex + "'");
  if (p.robot_checksum != robot.checksum)
    rob.fail("checksum", "this polytope was made for robot '" + p.robot_name + "' with description checksum " + hex +
                             ", but " + (robot.source_file.empty() ? "the loaded description" : robot.source_file) +
                             " ('" + robot.name + "') has checksum " + checksumHex(robot.checksum) +
                             ": the polytope is stale, regenerate it with `mft-space fit`");

  auto& th = root.child("thresholds");
  p.criteria.lti = th.orderedPair<Interval>("lti", /*allow_equal=*/true);
  p.criteria.raci = th.orderedPair<Interval>("raci_N_per_sqrt_kg", /*allow_equal=*/true);
  if (!parseRaciForm(th.text("raci_form"), &p.criteria.raci_options.form))
    th.fail("raci_form", "expected 'optimal' or 'fixed'");
  p.criteria.raci_options.accel_max_mps2 = th.positive("accel_max_mps2");
  p.criteria.raci_options.drive_k = th.positive("drive_k");
  p.criteria.raci_options.gearbox_efficiency = th.inRange("gearbox_efficiency", 1e-6, 1.0);
  p.criteria.raci_options.gravity = th.boolean("raci_gravity");
  p.criteria.raci_options.gravity_mps2 = robot.gravity_mps2;

  auto& grid = root.child("grid");
  p.fit.joint_step_rad = grid.positive("joint_step_rad");
  p.fit.cartesian_step_m = grid.positive("cartesian_step_m");
  p.fit.reachable_cells = grid.integer("reachable_cells");
  p.fit.preferable_cells = grid.integer("preferable_cells");

  auto& fit = root.child("fit");
  p.fit.edges = fit.integer("edges");
  p.fit.starts = fit.integer("starts");
  p.fit.rng_seed = static_cast<unsigned>(fit.integer("rng_seed"));
  p.fit.area_rad2 = fit.nonNegative("area_rad2");
  p.fit.coverage = fit.inRange("coverage", 0.0, 1.0);
  p.fit.r_max_rad = fit.nonNegative("r_max_rad");
  p.fit.bad_cells_inside = fit.integer("bad_cells_inside");
  if (p.fit.edges != kMftLegEdges)
    fit.fail("edges", "the WBC's MFT constraint needs a hexagon per leg (12 rows), this file has " +
                          std::to_string(p.fit.edges) + " edges");
  if (p.fit.bad_cells_inside != 0)
    fit.fail("bad_cells_inside", "the polygon contains non-preferable cells: it is not a conservative approximation");

  auto& leg = root.child("leg_polygon");
  const auto a_leg = leg.numbers("A", 2 * kMftLegEdges);
  const auto b_leg = leg.numbers("b", kMftLegEdges);
  const auto verts = leg.numbers("vertices", 0);
  if (verts.size() % 2 != 0 || verts.size() < 6) leg.fail("vertices", "expected a flat list of at least 3 (q_rear, q_fore) pairs");
  p.leg.A.resize(kMftLegEdges, 2);
  p.leg.b.resize(kMftLegEdges);
  for (int k = 0; k < kMftLegEdges; ++k) {
    p.leg.A.row(k) = flatRow(a_leg, k, 2);
    p.leg.b[k] = b_leg[k];
    if (std::abs(p.leg.A.row(k).norm() - 1.0) > 1e-6)
      leg.fail("A", "row " + std::to_string(k) + " is not a unit vector (norm " + fmt(p.leg.A.row(k).norm()) + ")");
  }
  for (std::size_t i = 0; i + 1 < verts.size(); i += 2) p.leg.vertices.emplace_back(verts[i], verts[i + 1]);

  auto& aug = root.child("augmented");
  const auto a = aug.numbers("A", static_cast<std::size_t>(kMftRows) * kNa);
  const auto b = aug.numbers("b", kMftRows);
  buildAugmented(p.leg, &p);
  for (int k = 0; k < kMftRows; ++k) {
    if ((flatRow(a, k, kNa) - p.A.row(k)).cwiseAbs().maxCoeff() > 1e-9)
      aug.fail("A", "row " + std::to_string(k) + " differs from blkdiag(leg_polygon.A, leg_polygon.A)");
    if (std::abs(b[k] - p.b[k]) > 1e-9) aug.fail("b", "element " + std::to_string(k) + " differs from [leg_polygon.b; leg_polygon.b]");
  }
  return p;
}

}  // namespace

MftPolytope loadMftPolytope(const std::string& path, const RobotDescription& robot) {
  return config::loadStrictFile(path, [&](StrictNode& root) { return read(root, robot); });
}

MftPolytope parseMftPolytope(const std::string& text, const std::string& origin, const RobotDescription& robot) {
  return config::parseStrictString(text, origin, [&](StrictNode& root) { return read(root, robot); });
}

void writeMftPolytope(std::ostream& out, const MftPolytope& p, const std::vector<std::string>& header) {
  for (const auto& h : header) out << "# " << h << "\n";
  const auto& c = p.criteria;
  const auto& f = p.fit;
  out << "schema_version: 1\n"
      << "robot:\n"
      << "  name: " << p.robot_name << "\n"
      << "  checksum: \"" << checksumHex(p.robot_checksum) << "\"   # robot description checksum (checksumHex)\n"
      << "thresholds:                      # preferable: every index inside its range (paper Definition 1)\n"
      << "  lti: [" << fmt(c.lti.lo) << ", " << fmt(c.lti.hi) << "]\n"
      << "  raci_N_per_sqrt_kg: [" << fmt(c.raci.lo) << ", " << fmt(c.raci.hi) << "]\n"
      << "  raci_form: " << raciFormName(c.raci_options.form) << "            # optimal ratio or fixed drive\n"
      << "  accel_max_mps2: " << fmt(c.raci_options.accel_max_mps2) << "\n"
      << "  drive_k: " << fmt(c.raci_options.drive_k) << "                     # n sqrt(J_m), fixed-drive form\n"
      << "  gearbox_efficiency: " << fmt(c.raci_options.gearbox_efficiency) << "\n"
      << "  raci_gravity: " << (c.raci_options.gravity ? "true" : "false") << "\n"
      << "grid:\n"
      << "  joint_step_rad: " << fmt(f.joint_step_rad) << "\n"
      << "  cartesian_step_m: " << fmt(f.cartesian_step_m) << "\n"
      << "  reachable_cells: " << f.reachable_cells << "         # joint-space grid nodes\n"
      << "  preferable_cells: " << f.preferable_cells << "\n"
      << "fit:\n"
      << "  edges: " << f.edges << "\n"
      << "  starts: " << f.starts << "\n"
      << "  rng_seed: " << f.rng_seed << "\n"
      << "  area_rad2: " << fmt(f.area_rad2) << "\n"
      << "  coverage: " << fmt(f.coverage) << "          # preferable nodes inside / all preferable nodes\n"
      << "  r_max_rad: " << fmt(f.r_max_rad) << "         # condition 2: uncovered preferable nodes lie this close\n"
      << "  bad_cells_inside: " << f.bad_cells_inside << "               # condition 1\n"
      << "leg_polygon:                     # A_leg [q_rear, q_fore] <= b_leg, same for both legs\n"
      << "  A:                             # row-major, " << p.leg.A.rows() << " x 2, unit-norm rows\n";
  // Flow sequences split over lines stay one list for YAML; one row per line keeps the file readable.
  auto block = [&](const auto& m, const char* indent) {
    out << indent << "[";
    for (int r = 0; r < m.rows(); ++r) {
      std::string row = rowList(m, r);
      row = row.substr(1, row.size() - 2);
      out << (r ? ",\n" + std::string(indent) + " " : "") << row;
    }
    out << "]\n";
  };
  block(p.leg.A, "    ");
  out << "  b: " << list(p.leg.b.data(), static_cast<int>(p.leg.b.size())) << "\n";
  Eigen::Matrix<double, Eigen::Dynamic, 2> V(p.leg.vertices.size(), 2);
  for (std::size_t i = 0; i < p.leg.vertices.size(); ++i) V.row(i) = p.leg.vertices[i].transpose();
  out << "  vertices:                      # counter-clockwise [q_rear, q_fore] pairs, flattened\n";
  block(V, "    ");
  out << "augmented:                       # the paper's A q_a <= b, q_a = [q4, q6, q8, q10]\n"
      << "  A:                             # row-major 12 x 4 = blkdiag(A_leg, A_leg)\n";
  block(p.A, "    ");
  out << "  b: " << list(p.b.data(), kMftRows) << "\n";
}

}  // namespace mft::model
