#include "wbc/wbc_reference.hpp"

#include <cmath>

namespace mft::wbc {

bool WbcReference::allFinite() const {
  for (const Setpoint1* s : {&base_z, &base_pitch, &base_x})
    if (!std::isfinite(s->pos) || !std::isfinite(s->vel) || !std::isfinite(s->acc)) return false;
  return foot_pos.allFinite() && foot_vel.allFinite() && foot_acc.allFinite();
}

}  // namespace mft::wbc
