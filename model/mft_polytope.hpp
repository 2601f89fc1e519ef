#pragma once
// The offline MFT preferable polytope (config/mft_space.yaml, written by tools/mft-space): per-leg polygon
// A_leg q <= b_leg in (q_rear, q_fore) and the paper's augmented A q_a <= b over q_a = [q4, q6, q8, q10],
// A = blkdiag(A_leg, A_leg) (12x4, unit-norm rows). The WBC builds its soft constraint C qdd <= d + eps from A, b.
// The file records the robot description checksum; loading it for another description is refused.
#include <Eigen/Core>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "model/coordinates.hpp"
#include "model/mft_criteria.hpp"
#include "model/mft_polygon.hpp"
#include "model/robot_description.hpp"

namespace mft::model {

constexpr int kMftLegEdges = 6;                   // the paper's hexagon
constexpr int kMftRows = kNumLegs * kMftLegEdges;  // 12

struct MftLegPolygon {
  Eigen::Matrix<double, Eigen::Dynamic, 2> A;  // unit-norm rows over (q_rear, q_fore)
  Eigen::VectorXd b;
  std::vector<Eigen::Vector2d> vertices;        // counter-clockwise
  bool contains(double q_rear, double q_fore, double tol = 0.0) const;
  // Paper (10) for this leg alone: max(A_leg [q_rear, q_fore] - b_leg) [rad], <= 0 inside.
  double violation(double q_rear, double q_fore) const;
  static MftLegPolygon fromHalfPlanes(const HalfPlanePolygon& p);
};

// How a polytope is fitted (mft-space's defaults), and what the fit gave.
struct MftFitSettings {
  double joint_step_rad = 0.01;
  double cartesian_step_m = 0.01;
  int edges = kMftLegEdges;
  int starts = 24;
  unsigned rng_seed = 1;
};
struct MftFitSummary : MftFitSettings {
  double area_rad2 = 0.0;
  double coverage = 0.0;        // fraction of preferable joint-grid nodes inside the polygon
  double r_max_rad = 0.0;       // condition 2: largest distance of an uncovered preferable node to the polygon
  int bad_cells_inside = 0;     // condition 1: must be 0
  int preferable_cells = 0;
  int reachable_cells = 0;
};

// Paper (10): the largest row of A q - b; <= 0 inside the preferable polytope. The one computation of the MFT
// violation: over q_a = [q4, q6, q8, q10] with the augmented A (the WBC's diagnostics, mft-closedloop), over one
// leg's rows of it (MftPolytope::legViolation, `mft-space violation`), or over (q_rear, q_fore) with a leg polygon.
// Fixed-size arguments allocate nothing (the controller calls it every tick).
template <typename DerivedA, typename DerivedB, typename DerivedQ>
double polytopeViolation(const Eigen::MatrixBase<DerivedA>& A, const Eigen::MatrixBase<DerivedB>& b,
                         const Eigen::MatrixBase<DerivedQ>& q) {
  return (A * q - b).maxCoeff();
}

struct MftPolytope {
  Eigen::Matrix<double, kMftRows, kNa> A = Eigen::Matrix<double, kMftRows, kNa>::Zero();
  Eigen::Matrix<double, kMftRows, 1> b = Eigen::Matrix<double, kMftRows, 1>::Zero();
  MftLegPolygon leg;
  MftCriteria criteria;  // the thresholds and RACI form it was made with
  MftFitSummary fit;
  std::string robot_name;
  std::uint64_t robot_checksum = 0;
  std::string source_file;

  // q_a = [q4, q6, q8, q10].
  bool contains(const VectorA& q_a, double tol = 0.0) const { return violation(q_a) <= tol; }
  double violation(const VectorA& q_a) const { return polytopeViolation(A, b, q_a); }
  // Leg 0 (right: q4, q6) or 1 (left: q8, q10): the rows of (10) that belong to that leg.
  double legViolation(int leg_index, const VectorA& q_a) const {
    const int first = leg_index * kMftLegEdges;
    return polytopeViolation(A.middleRows<kMftLegEdges>(first), b.segment<kMftLegEdges>(first), q_a);
  }
};

// blkdiag(A_leg, A_leg) and [b_leg; b_leg]; needs a hexagon.
void buildAugmented(const MftLegPolygon& leg, MftPolytope* p);

// Strict loader (unknown / missing keys, wrong sizes, non-unit rows, an A or b that is not the augmented leg
// polygon, and a checksum different from `robot`'s are all ConfigErrors naming the file and key).
MftPolytope loadMftPolytope(const std::string& path, const RobotDescription& robot);
MftPolytope parseMftPolytope(const std::string& yaml_text, const std::string& origin, const RobotDescription& robot);

// Writes the YAML that the loader reads. `header` lines are written as comments at the top.
void writeMftPolytope(std::ostream& out, const MftPolytope& p, const std::vector<std::string>& header);

}  // namespace mft::model
