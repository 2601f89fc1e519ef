#pragma once
// Where a tool finds the project's data files (the configuration folder, the plotting scripts). A build folder's
// executables use the source tree's paths compiled into them; an installed executable (cmake --install, the
// .deb) in <prefix>/bin uses <prefix>/share/mft_wbc, so an install works without the source tree and without
// --config-dir. One rule for every tool (docs/guide/library.md#layout-of-an-install).
#include <string>

namespace mft::config {

// <prefix>/share/mft_wbc when this process's executable is <prefix>/bin/NAME and that folder holds
// config/robot.yaml; "" otherwise (a build folder, or a program of someone else's that links the libraries).
const std::string& installedDataDir();

// The configuration folder: <installed>/config, else build_tree_dir.
std::string configDirFor(const std::string& build_tree_dir);

// A data file: <installed>/installed_relative (e.g. "scripts/mft-plot.py"), else build_tree_path.
std::string dataFileFor(const std::string& installed_relative, const std::string& build_tree_path);

}  // namespace mft::config
