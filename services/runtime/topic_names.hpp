// DDS topic names. The code names a topic by its message type ("SensorData"); on the wire it is the name ROS 2
// gives topic /mft/sensor_data: "rt/" + "mft/" + the snake_case name, so ROS 2 tools (ros2 topic echo, rosbag2,
// PlotJuggler, Foxglove) see our topics with the ros2/mft message package (docs/guide/interop.md#ros-2).
#pragma once

#include <cctype>
#include <string>

namespace mft::services {

// How recordings say which names the stack used (rawlog metadata `dds_naming`; older files: "plain", the
// type name as topic name and types mft::msg::<Name>).
inline constexpr const char* kDdsNaming = "ros2";
inline constexpr const char* kDdsTopicPrefix = "rt/mft/";

// "SensorData" -> "rt/mft/sensor_data", "WbcDiagnostics" -> "rt/mft/wbc_diagnostics".
inline std::string ddsTopicName(const std::string& type_name) {
  std::string out = kDdsTopicPrefix;
  for (std::size_t i = 0; i < type_name.size(); ++i) {
    const auto c = static_cast<unsigned char>(type_name[i]);
    if (std::isupper(c)) {
      if (i > 0) out += '_';
      out += static_cast<char>(std::tolower(c));
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace mft::services
