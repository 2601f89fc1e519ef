// The topic types under the names the code uses: mft::msg::<Name> for the generated mft::msg::dds_::<Name>_,
// the name ROS 2's rmw_fastrtps gives a message of package `mft` on the wire (idl/mft_msgs.idl,
// docs/guide/interop.md#ros-2), with the topic registry's descriptors (idl/topics.yaml, generated into mft_topics.hpp:
// MFT_MSG_TYPES, MFT_TOPICS, kTopics, visitFields; docs/reference/architecture.md#the-topic-registry).
#pragma once

#include "mft_msgs.h"
#include "mft_topics.hpp"
