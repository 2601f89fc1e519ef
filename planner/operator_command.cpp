#include "planner/operator_command.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/strict_yaml.hpp"

namespace mft::planner {

CommandLimits commandLimits(const model::RobotDescription& robot, const CommandParams& params,
                            const std::string& config_file) {
  const double l1 = robot.thigh.length_m, l2 = robot.shank.length_m;
  CommandLimits lim;
  lim.height_min_m = std::max(std::abs(l2 - l1) + params.height_margin_m, params.height_window_m[0]);
  lim.height_max_m = std::min(l1 + l2 - params.height_margin_m, params.height_window_m[1]);
  lim.max_speed_mps = params.max_speed_mps;
  if (!(lim.height_min_m < lim.height_max_m)) {
    std::ostringstream os;
    os << config_file << ": command.height_window_m: no base height is both in the window and in the legs' reach ["
       << std::abs(l2 - l1) + params.height_margin_m << ", " << l1 + l2 - params.height_margin_m << "] m";
    throw config::ConfigError(os.str());
  }
  return lim;
}

CommandResult checkCommand(const OperatorCommand& cmd, const CommandLimits& limits) {
  std::ostringstream why;
  if (!std::isfinite(cmd.z_cmd)) {
    why << "height command is not a finite number";
  } else if (!std::isfinite(cmd.v_cmd)) {
    why << "speed command is not a finite number";
  } else if (cmd.z_cmd < limits.height_min_m || cmd.z_cmd > limits.height_max_m) {
    why << "height " << cmd.z_cmd << " m outside the reachable range [" << limits.height_min_m << ", "
        << limits.height_max_m << "] m";
  } else if (std::abs(cmd.v_cmd) > limits.max_speed_mps) {
    why << "speed " << cmd.v_cmd << " m/s beyond the limit +-" << limits.max_speed_mps << " m/s";
  } else if (cmd.mode != LocomotionMode::Stand && cmd.mode != LocomotionMode::StepInPlace &&
             cmd.mode != LocomotionMode::Walk) {
    why << "unknown locomotion mode " << static_cast<int>(cmd.mode);
  } else {
    return {true, {}};
  }
  return {false, why.str()};
}

CommandGate::CommandGate(const CommandLimits& limits, const OperatorCommand& initial)
    : limits_(limits), current_(initial) {
  const auto r = checkCommand(initial, limits);
  if (!r.accepted) throw config::ConfigError("initial planner command rejected: " + r.reason);
}

CommandResult CommandGate::submit(const OperatorCommand& cmd) {
  auto r = checkCommand(cmd, limits_);
  if (r.accepted) current_ = cmd;
  else ++rejected_;
  return r;
}

}  // namespace mft::planner
