// The generated DDS type supports under the names the code uses: mft::msg::<Name>PubSubType for
// mft::msg::dds_::<Name>_PubSubType (idl/msg_types.hpp).
#pragma once

#include "idl/msg_types.hpp"
#include "mft_msgsPubSubTypes.h"

namespace mft::msg {
using SensorDataPubSubType = dds_::SensorData_PubSubType;
using GroundTruthPubSubType = dds_::GroundTruth_PubSubType;
using RobotStatePubSubType = dds_::RobotState_PubSubType;
using OperatorCommandPubSubType = dds_::OperatorCommand_PubSubType;
using ReferencePubSubType = dds_::Reference_PubSubType;
using JointCommandPubSubType = dds_::JointCommand_PubSubType;
using WbcDiagnosticsPubSubType = dds_::WbcDiagnostics_PubSubType;
using RecorderProgressPubSubType = dds_::RecorderProgress_PubSubType;
using DisturbancePubSubType = dds_::Disturbance_PubSubType;
using CommandVerdictPubSubType = dds_::CommandVerdict_PubSubType;
}  // namespace mft::msg
