// The topic types under the names the code uses: mft::msg::<Name> for the generated mft::msg::dds_::<Name>_,
// the name ROS 2's rmw_fastrtps gives a message of package `mft` on the wire (idl/mft_msgs.idl,
// docs/interop.md#ros-2).
#pragma once

#include "mft_msgs.h"

namespace mft::msg {
using SensorData = dds_::SensorData_;
using GroundTruth = dds_::GroundTruth_;
using RobotState = dds_::RobotState_;
using OperatorCommand = dds_::OperatorCommand_;
using Reference = dds_::Reference_;
using JointCommand = dds_::JointCommand_;
using WbcDiagnostics = dds_::WbcDiagnostics_;
using RecorderProgress = dds_::RecorderProgress_;
using Disturbance = dds_::Disturbance_;
using CommandVerdict = dds_::CommandVerdict_;
}  // namespace mft::msg
