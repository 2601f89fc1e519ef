#pragma once
// The operator command [z_cmd, v_cmd] + mode, and the gate that keeps commands inside the robot's range:
// a rejected command leaves the last valid one in force and says why.
#include <cstdint>
#include <string>

#include "model/robot_description.hpp"
#include "planner/planner_config.hpp"

namespace mft::planner {

struct OperatorCommand {
  double z_cmd = 0.0;  // base (hip axis) height above the ground plane z = 0 [m]
  double v_cmd = 0.0;  // average sagittal speed [m/s]; ignored unless mode == Walk
  LocomotionMode mode = LocomotionMode::Stand;
};

struct CommandLimits {
  double height_min_m = 0.0, height_max_m = 0.0;
  double max_speed_mps = 0.0;
};

// Reach range of a leg [|l2 - l1| + margin, l1 + l2 - margin] intersected with the configured window.
// Throws mft::config::ConfigError if the intersection is empty (the planner config does not fit the robot).
CommandLimits commandLimits(const model::RobotDescription& robot, const CommandParams& params,
                            const std::string& config_file);

struct CommandResult {
  bool accepted = false;
  std::string reason;  // empty when accepted
};

// Checks one command against the limits (finite numbers, height range, speed limit, a known mode).
CommandResult checkCommand(const OperatorCommand& cmd, const CommandLimits& limits);

// Holds the command in force.
class CommandGate {
 public:
  CommandGate(const CommandLimits& limits, const OperatorCommand& initial);  // throws if `initial` is invalid
  CommandResult submit(const OperatorCommand& cmd);
  const OperatorCommand& current() const { return current_; }
  const CommandLimits& limits() const { return limits_; }
  std::uint64_t rejectedCount() const { return rejected_; }

 private:
  CommandLimits limits_;
  OperatorCommand current_;
  std::uint64_t rejected_ = 0;
};

}  // namespace mft::planner
