#include "services/record/recording_files.hpp"

#include <signal.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"
#include "services/record/rawlog_format.hpp"
#include "services/runtime/topic_names.hpp"

namespace mft::services {

namespace fs = std::filesystem;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

bool pidAlive(long pid) { return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

}  // namespace

int firstPiece(const std::string& output) {
  const std::string sidecar = rawlog::sidecarName(output);
  if (!fs::exists(sidecar)) return 0;
  try {
    const YAML::Node n = YAML::LoadFile(sidecar)["recording"];
    if (!n || n["status"].as<std::string>("") != "recording") return 0;
    if (n["parent_pid"].as<long>(0) != static_cast<long>(getppid()) || pidAlive(n["recorder_pid"].as<long>(0))) return 0;
  } catch (const YAML::Exception&) {
    return 0;
  }
  int piece = 1;
  while (fs::exists(rawlog::pieceName(output, piece))) ++piece;
  return piece;
}

void refuseOrClearOldRecording(const std::string& output, bool overwrite, bool check_only, const CommandLine& cli) {
  const std::string sidecar = rawlog::sidecarName(output);
  std::error_code ec;
  const bool exists = fs::exists(output, ec) || fs::exists(sidecar, ec);
  if (!exists) return;
  if (!overwrite)
    cli.fail(output + " already exists: refusing to replace a recording (--overwrite replaces it)");
  if (fs::is_directory(output, ec)) cli.fail("--output " + output + " is a directory");
  if (check_only) return;  // --check-config changes nothing
  fs::remove(output, ec);
  fs::remove(sidecar, ec);
  for (int piece = 1; fs::exists(rawlog::pieceName(output, piece), ec); ++piece) fs::remove(rawlog::pieceName(output, piece), ec);
}

void storeConfiguration(const std::string& config_dir, const std::string& scenario_file, const chain::Scenario& scenario,
                        const model::RobotDescription& robot, const CommandLine& cli, rawlog::Metadata* md) {
  auto config_file = [&](const std::string& name) { return config_dir + "/" + name; };
  md->created_utc = utcNow();
  md->scenario_file = fs::absolute(scenario_file).string();
  md->scenario_name = scenario.name;
  md->controller = scenario.controller;
  md->robot_checksum = model::checksumHex(robot.checksum);
  md->profiles = scenario.profiles;
  md->dds_naming = kDdsNaming;
  const auto& profiles = config::activeProfiles();
  for (const char* f : {"robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml"}) {
    if (!fs::exists(config_file(f))) cli.fail("missing configuration " + config_file(f));
    try {
      md->config[f] = profiles.applyToText(config::profileStemOf(f), readFile(config_file(f)), config_file(f));
    } catch (const config::ConfigError& e) {
      cli.fail(e.what());
    }
  }
  for (const auto& name : md->profiles) md->config["profiles/" + name + ".yaml"] = readFile(config_file("profiles/" + name + ".yaml"));
  md->config["scenario"] = readFile(scenario_file);
  const std::string terrain = "terrain/" + scenario.terrain + ".yaml";
  if (fs::exists(config_file(terrain))) md->config[terrain] = readFile(config_file(terrain));
}

}  // namespace mft::services
