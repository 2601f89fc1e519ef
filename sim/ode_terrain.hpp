#pragma once
// Internal: the terrain's static ODE geoms (no bodies) in their own simple space, in a fixed order.
// Solids are lowered by the foot sphere radius so that the sphere's centre (the model's foot point) rests on
// the nominal height (by radius / cos(angle) on slopes: exact there too).
#include <ode/ode.h>

#include "sim/terrain.hpp"

namespace mft::sim {

class OdeTerrain {
 public:
  OdeTerrain(const Terrain& terrain, double foot_radius);
  ~OdeTerrain();
  OdeTerrain(const OdeTerrain&) = delete;
  OdeTerrain& operator=(const OdeTerrain&) = delete;

  dSpaceID space() const { return space_; }
  // Highest collision surface hit by a downward ray at x from z_from; NaN if none.
  double rayDown(double x, double z_from) const;
  // Deepest penetration of a free sphere (radius r, centre (x, z)) into the terrain; <= 0 when apart
  // (then minus a lower bound of the gap is not available: returns 0).
  double sphereDepth(double x, double z, double r) const;

 private:
  void addBox(double x_lo, double x_hi, double top, double thickness);
  void addSlab(double xa, double za, double xb, double zb, double thickness);
  dSpaceID space_ = nullptr;
};

}  // namespace mft::sim
