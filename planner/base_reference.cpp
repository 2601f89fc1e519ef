#include "planner/base_reference.hpp"

#include <algorithm>

namespace mft::planner {

HeightPitchReference heightPitchReference(double z_ref, double z_cmd, double max_rate, double dt) {
  const double max_step = max_rate * dt;
  const double dz = std::clamp(z_cmd - z_ref, -max_step, max_step);
  HeightPitchReference r;
  r.base_z = {z_ref + dz, dt > 0.0 ? dz / dt : 0.0, 0.0};
  return r;
}

}  // namespace mft::planner
