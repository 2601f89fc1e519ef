#pragma once
// The project's configuration as the fuzz targets' baseline: the text of a shipped file and the robot, read once
// from the source tree's config/ (MFT_CONFIG_DIR).
#include <fstream>
#include <sstream>
#include <string>

#include "model/robot_description.hpp"

namespace mft::fuzz {

inline std::string configFile(const std::string& name) {
  std::ifstream in(std::string(MFT_CONFIG_DIR) + "/" + name);
  std::stringstream text;
  if (!(text << in.rdbuf())) throw std::runtime_error(std::string(MFT_CONFIG_DIR) + "/" + name + ": cannot read");
  return text.str();
}

inline const model::RobotDescription& shippedRobot() {
  static const model::RobotDescription robot = model::loadRobotDescription(std::string(MFT_CONFIG_DIR) + "/robot.yaml");
  return robot;
}

}  // namespace mft::fuzz
