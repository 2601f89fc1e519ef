// The topic types under the names the code uses: mft::msg::<Name> for the generated mft::msg::dds_::<Name>_,
// the name ROS 2's rmw_fastrtps gives a message of package `mft` on the wire (idl/mft_msgs.idl,
// docs/interop.md#ros-2).
#pragma once

#include "mft_msgs.h"

// Every struct of idl/mft_msgs.idl, for the aliases here and in idl/msg_pubsub.hpp.
#define MFT_MSG_TYPES(X) \
  X(SensorData)          \
  X(GroundTruth)         \
  X(RobotState)          \
  X(OperatorCommand)     \
  X(Reference)           \
  X(JointCommand)        \
  X(WbcDiagnostics)      \
  X(RecorderProgress)    \
  X(Disturbance)         \
  X(CommandVerdict)      \
  X(ConfigChange)

namespace mft::msg {
#define MFT_MSG_TYPE_ALIAS(Name) using Name = dds_::Name##_;
MFT_MSG_TYPES(MFT_MSG_TYPE_ALIAS)
#undef MFT_MSG_TYPE_ALIAS
}  // namespace mft::msg
