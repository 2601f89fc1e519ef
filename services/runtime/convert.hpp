#pragma once
// Conversions between the libraries' plain structs and the DDS messages. Kept in one place so that a field
// added to a topic touches one file. Copies only: no allocation.
#include "idl/msg_types.hpp"
#include "model/robot_io.hpp"
#include "planner/operator_command.hpp"
#include "planner/plan_output.hpp"
#include "wbc/wbc_diagnostics.hpp"
#include "wbc/wbc_reference.hpp"

namespace mft::services {

inline std::uint64_t toStampNs(double time_s) { return static_cast<std::uint64_t>(time_s * 1e9 + 0.5); }
inline double fromStampNs(std::uint64_t ns) { return static_cast<double>(ns) * 1e-9; }

void toMsg(const model::SensorReadings& in, msg::SensorData* out);
void fromMsg(const msg::SensorData& in, model::SensorReadings* out);

void toMsg(const model::GroundTruthState& in, msg::GroundTruth* out);
void fromMsg(const msg::GroundTruth& in, model::GroundTruthState* out);

void toMsg(const model::RobotStateEstimate& in, msg::RobotState* out);
void fromMsg(const msg::RobotState& in, model::RobotStateEstimate* out);

void toMsg(const model::ActuatorCommand& in, std::uint64_t stamp_ns, std::uint64_t seq, msg::JointCommand* out);
void fromMsg(const msg::JointCommand& in, model::ActuatorCommand* out);

void toMsg(const planner::PlanOutput& in, msg::Reference* out);
// The same with the controller's part already mapped (`reference` = chain::referenceFromPlan(in), as the planner
// node holds it).
void toMsg(const planner::PlanOutput& in, const wbc::WbcReference& reference, msg::Reference* out);
void fromMsg(const msg::Reference& in, wbc::WbcReference* out);

void toMsg(const wbc::WbcDiagnostics& in, std::uint64_t stamp_ns, msg::WbcDiagnostics* out);

// The IDL's LOCOMOTION_* octet as the project's one mode type; an unknown octet reads as Stand (mft-planner
// rejects such a command before it takes effect).
planner::LocomotionMode locomotionModeFromMsg(std::uint8_t mode);
void fromMsg(const msg::OperatorCommand& in, planner::OperatorCommand* out);

}  // namespace mft::services
