#include "services/runtime/service_context.hpp"

#include <cstdio>
#include <fstream>

#include "model/config/strict_yaml.hpp"
#include "services/runtime/scenario_limits.hpp"

namespace mft::services {

void ServiceContext::declareOptions(CommandLine& cli) {
  cli.option("domain", "DDS domain id (0..232)", "", true);
  cli.option("scenario", "scenario file (config/scenarios/*.yaml)", "", true);
  cli.option("mode", "lockstep | realtime", "lockstep");
  cli.option("config-dir", "configuration folder", MFT_CONFIG_DIR);
  cli.option("summary", "write a JSON summary to this file at exit");
  cli.flag("rt", "try SCHED_FIFO + mlockall (falls back with a warning)");
  cli.option("secure", "DDS Security: the directory made by scripts/make-security.sh (this service's identity)");
  cli.option("profiles", "DDS QoS profile file (default: dds_profiles.xml of --config-dir; a multi-host stack gives "
             "each host its own: its address, its peers or discovery server, docs/distributed.md)");
}

std::string ServiceContext::profilesFile(const CommandLine& cli) {
  const std::string file = cli.get("profiles");
  return file.empty() ? cli.get("config-dir") + "/dds_profiles.xml" : file;
}

ServiceContext::ServiceContext(const std::string& service, const CommandLine& cli) : service_(service) {
  const std::string mode = cli.get("mode");
  if (mode == "lockstep") mode_ = LoopMode::Lockstep;
  else if (mode == "realtime") mode_ = LoopMode::Realtime;
  else cli.fail("--mode: expected lockstep or realtime, got '" + mode + "'");
  const int domain = static_cast<int>(cli.getInt("domain", 0, kMaxDomainId));
  config_dir_ = cli.get("config-dir");
  summary_file_ = cli.get("summary");
  try {
    robot_ = model::loadRobotDescription(configFile("robot.yaml"));
    scenario_ = loadScenario(cli.get("scenario"));
    checkScenarioLimits(scenario_, robot_, configFile("planner.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  if (cli.isSet("rt")) tryRealtimeScheduling(80);
  try {
    participant_ = std::make_unique<DdsParticipant>(domain, profilesFile(cli), service,
                                                    SecurityOptions{cli.get("secure"), securityIdentity(service)});
  } catch (const DdsError& e) {
    cli.fail(e.what());
  }
}

void ServiceContext::writeSummary(const std::string& json) const {
  if (summary_file_.empty()) return;
  const std::string tmp = summary_file_ + ".tmp";
  {
    std::ofstream out(tmp);
    out << json << "\n";
    if (!out) {
      std::fprintf(stderr, "%s: cannot write the summary %s\n", service_.c_str(), summary_file_.c_str());
      return;
    }
  }
  std::rename(tmp.c_str(), summary_file_.c_str());  // never a half-written summary
}

}  // namespace mft::services
