#include "services/runtime/live_tuning.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"

namespace mft::services {

std::string tuningStatusFile(const std::string& summary_file) {
  const std::string suffix = ".summary.json";
  if (summary_file.size() <= suffix.size() ||
      summary_file.compare(summary_file.size() - suffix.size(), suffix.size(), suffix) != 0)
    return summary_file.empty() ? "" : summary_file + ".tuning.json";
  return summary_file.substr(0, summary_file.size() - suffix.size()) + ".tuning.json";
}

bool writeTuningStatus(const std::string& path, const std::string& json) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!(out << json << "\n")) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

std::string configTextInForce(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  if (!in || !(text << in.rdbuf())) throw config::ConfigError(path + ": cannot read the file");
  const auto& profiles = config::activeProfiles();
  const std::string stem = config::profileStemOf(path);
  if (!stem.empty() && profiles.touches(stem)) return profiles.applyToText(stem, text.str(), path);
  return text.str();
}

}  // namespace mft::services
