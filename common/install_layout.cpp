#include "common/install_layout.hpp"

#include <filesystem>
#include <system_error>

namespace mft::config {

namespace {

std::string findInstalledDataDir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec || exe.empty()) return "";
  // bin/ and share/ are siblings in every install layout we produce (GNUInstallDirs: bin, share).
  const fs::path share = exe.parent_path().parent_path() / "share" / "mft_wbc";
  if (!fs::is_regular_file(share / "config" / "robot.yaml", ec)) return "";
  return share.lexically_normal().string();
}

}  // namespace

const std::string& installedDataDir() {
  static const std::string dir = findInstalledDataDir();
  return dir;
}

std::string configDirFor(const std::string& build_tree_dir) {
  return installedDataDir().empty() ? build_tree_dir : installedDataDir() + "/config";
}

std::string dataFileFor(const std::string& installed_relative, const std::string& build_tree_path) {
  return installedDataDir().empty() ? build_tree_path : installedDataDir() + "/" + installed_relative;
}

}  // namespace mft::config
