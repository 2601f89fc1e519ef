#include "sim/ode_terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mft::sim {
namespace {

constexpr double kFar = 1000.0;       // level ground before and after the segments [m]
constexpr double kWidth = 2.0;        // lateral extent of every solid (ODE z) [m]
constexpr double kThickness = 1.0;    // depth of the solids below their top [m]

struct Hits {
  double best = -std::numeric_limits<double>::infinity();
  double depth = 0.0;
};

void rayCallback(void* data, dGeomID o1, dGeomID o2) {
  dContactGeom c[4];
  const int n = dCollide(o1, o2, 4, c, sizeof(dContactGeom));
  auto* hits = static_cast<Hits*>(data);
  for (int i = 0; i < n; ++i) hits->best = std::max(hits->best, static_cast<double>(c[i].pos[1]));
}

void depthCallback(void* data, dGeomID o1, dGeomID o2) {
  dContactGeom c[8];
  const int n = dCollide(o1, o2, 8, c, sizeof(dContactGeom));
  auto* hits = static_cast<Hits*>(data);
  for (int i = 0; i < n; ++i) hits->depth = std::max(hits->depth, static_cast<double>(c[i].depth));
}

}  // namespace

void OdeTerrain::addBox(double x_lo, double x_hi, double top, double thickness) {
  dGeomID box = dCreateBox(space_, x_hi - x_lo, thickness, kWidth);  // ODE (x, y, z) = project (x, z, -y)
  dGeomSetPosition(box, 0.5 * (x_lo + x_hi), top - 0.5 * thickness, 0.0);
}

void OdeTerrain::addSlab(double xa, double za, double xb, double zb, double thickness) {
  // A box rotated about z whose top face runs from (xa, za) to (xb, zb).
  const double angle = std::atan2(zb - za, xb - xa), c = std::cos(angle), sn = std::sin(angle);
  dGeomID box = dCreateBox(space_, std::hypot(xb - xa, zb - za), thickness, kWidth);
  dGeomSetPosition(box, 0.5 * (xa + xb) + 0.5 * thickness * sn, 0.5 * (za + zb) - 0.5 * thickness * c, 0.0);
  dMatrix3 R;
  dRFromAxisAndAngle(R, 0, 0, 1, angle);
  dGeomSetRotation(box, R);
}

OdeTerrain::OdeTerrain(const Terrain& terrain, double r) {
  space_ = dSimpleSpaceCreate(nullptr);
  // Runs of level ground between slopes get one floor box each: coplanar neighbouring boxes would give the
  // foot sphere spurious tilted contacts at their shared edge.
  double run_x0 = -kFar + std::min(terrain.start_x, 0.0);
  double level = terrain.start_height;
  for (const TerrainSegment& s : terrain.segments) {
    switch (s.type) {
      case SegmentType::Flat:
        break;
      case SegmentType::Board:
        addBox(s.x0, s.x1(), s.z0 + s.height - r, s.height + 0.1);
        break;
      case SegmentType::Rough:
        // One thin tilted box per cell: its top face is the straight line between two samples, so the union is
        // exactly the piecewise-linear profile (its ends lean under the neighbouring cells for slopes < 45 deg).
        // Not a heightfield: ODE 0.16's sphere-heightfield collider missed contacts near sample lines (the 5 mm
        // foot sphere sank 4.5 mm undetected), which boxes do not.
        for (std::size_t i = 0; i + 1 < s.samples.size(); ++i) {
          const double xa = s.x0 + static_cast<double>(i) * s.spacing, xb = xa + s.spacing;
          addSlab(xa, s.z0 + s.samples[i] - r, xb, s.z0 + s.samples[i + 1] - r, 0.1);
        }
        break;
      case SegmentType::Slope: {
        addBox(run_x0, s.x0, level - r, kThickness);
        const double drop = r / std::cos(s.angle_rad);  // lowered along the normal by r
        addSlab(s.x0, s.z0 - drop, s.x1(), s.endLevel() - drop, kThickness);
        run_x0 = s.x1();
        level = s.endLevel();
        break;
      }
    }
  }
  addBox(run_x0, std::max(terrain.endX(), 0.0) + kFar, level - r, kThickness);
}

OdeTerrain::~OdeTerrain() {
  dSpaceDestroy(space_);  // destroys the geoms it holds (cleanup mode on by default)
}

double OdeTerrain::rayDown(double x, double z_from) const {
  dGeomID ray = dCreateRay(nullptr, 1e3);
  dGeomRaySet(ray, x, z_from, 0.0, 0.0, -1.0, 0.0);
  Hits hits;
  dSpaceCollide2(ray, reinterpret_cast<dGeomID>(space_), &hits, rayCallback);
  dGeomDestroy(ray);
  return std::isfinite(hits.best) ? hits.best : std::numeric_limits<double>::quiet_NaN();
}

double OdeTerrain::sphereDepth(double x, double z, double r) const {
  dGeomID sphere = dCreateSphere(nullptr, r);
  dGeomSetPosition(sphere, x, z, 0.0);
  Hits hits;
  dSpaceCollide2(sphere, reinterpret_cast<dGeomID>(space_), &hits, depthCallback);
  dGeomDestroy(sphere);
  return hits.depth;
}

}  // namespace mft::sim
