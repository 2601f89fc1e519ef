#pragma once
// A text cut at every `separator` (empty pieces kept, no trailing empty piece): dotted keys, CSV lines, lists.
#include <sstream>
#include <string>
#include <vector>

namespace mft::config {

inline std::vector<std::string> splitOn(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, separator)) parts.push_back(item);
  return parts;
}

}  // namespace mft::config
