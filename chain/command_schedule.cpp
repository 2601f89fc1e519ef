#include "chain/command_schedule.hpp"

namespace mft::chain {

double commandedHeight(const Scenario& scenario, double t) {
  double z = scenario.commands.front().z_cmd_m;
  for (const auto& c : scenario.commands)
    if (c.at_s <= t) z = c.z_cmd_m;
  return z;
}

}  // namespace mft::chain
