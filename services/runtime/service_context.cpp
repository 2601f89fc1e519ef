#include "services/runtime/service_context.hpp"

#include <cstdio>
#include <fstream>

#include "common/install_layout.hpp"
#include "common/strict_yaml.hpp"
#include "chain/scenario_limits.hpp"

namespace mft::services {

void ServiceContext::declareOptions(CommandLine& cli) {
  cli.option("domain", "DDS domain id (0..232)", "", true);
  cli.option("scenario", "scenario file (config/scenarios/*.yaml)", "", true);
  cli.option("mode", "lockstep | realtime", "lockstep");
  cli.option("config-dir", "configuration folder", config::configDirFor(MFT_CONFIG_DIR));
  cli.option("summary", "write a JSON summary to this file at exit");
  cli.flag("rt", "try SCHED_FIFO + mlockall (falls back with a warning)");
  cli.option("rt-priority", "with --rt: the SCHED_FIFO priority (the supervisor's --rt-priorities chain gives the chain's "
             "services rising priorities along the chain)", "80");
  cli.option("rt-threads", "with --rt and --chain-shm: loop (only the 1 kHz threads take the --rt-priority, on the CPUs "
             "the service was started on; the other threads, DDS's own, SCHED_FIFO 1 on the other CPUs) or all (every "
             "thread at the --rt-priority, as with a DDS chain); docs/results/loop-benchmark.md", "loop");
  cli.option("secure", "DDS Security: the directory made by scripts/make-security.sh (this service's identity)");
  cli.option("profile", "configuration profile config/profiles/NAME.yaml, after the scenario's (repeatable, or a "
             "comma list; docs/guide/profiles.md)");
  cli.option("profiles", "DDS QoS profile file (default: dds_profiles.xml of --config-dir; a multi-host stack gives "
             "each host its own: its address, its peers or discovery server, docs/guide/distributed.md)");
  cli.option("chain-shm", "chain services: also carry the chain's topics through this POSIX shared-memory "
             "segment (/mft-chain-…; the supervisor names one per stack; docs/results/loop-benchmark.md)");
  cli.option("stack-services", "the names of the stack's services, comma-separated (the supervisor gives them): "
             "announced in DDS discovery, so that mft-cmd waits for every reader of a request, the recorder included");
  cli.flag("check-config", "load every configuration file this service reads (strict loaders) and the DDS profile "
           "file (Fast DDS's XML loader), then exit: 0 and 'configuration ok', or 2 and the error; starts nothing");
}

std::string ServiceContext::profilesFile(const CommandLine& cli) {
  const std::string file = cli.get("profiles");
  return file.empty() ? cli.get("config-dir") + "/dds_profiles.xml" : file;
}

std::string ServiceContext::stackServices(const CommandLine& cli) {
  const std::string names = cli.get("stack-services");
  if (names.size() > 200 || names.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-,") != std::string::npos)
    cli.fail("--stack-services: expected service names (a-z, 0-9, '-') separated by commas, at most 200 characters");
  return names;
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
    scenario_ = chain::loadScenario(cli.get("scenario"));
    profile_names_ = chain::activateRunProfiles(config_dir_, scenario_, cli.getAll("profile"));
    robot_ = model::loadRobotDescription(configFile("robot.yaml"));
    chain::checkScenarioLimits(scenario_, robot_, configFile("planner.yaml"));
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  check_only_ = cli.isSet("check-config");
  if (check_only_) {
    const std::string problem = checkProfilesFile(profilesFile(cli));
    if (!problem.empty()) cli.fail(problem);
    return;
  }
  const std::string chain_shm = cli.get("chain-shm");
  if (!chain_shm.empty() && !cli.get("secure").empty())
    cli.fail("--chain-shm: not with --secure (it would bypass DDS access control)");
  const std::string rt_threads = cli.get("rt-threads");
  if (rt_threads != "loop" && rt_threads != "all") cli.fail("--rt-threads: expected loop or all, got '" + rt_threads + "'");
  if (cli.isSet("rt")) {
    const int priority = static_cast<int>(cli.getInt("rt-priority", 1, 98));
    // On a DDS chain the 1 kHz work runs on DDS's threads: they must inherit SCHED_FIFO.
    if (rt_threads == "loop" && !chain_shm.empty()) tryRealtimeLoopThreads(priority);
    else tryRealtimeScheduling(priority);
  }
  try {
    participant_ = std::make_unique<DdsParticipant>(domain, profilesFile(cli), service,
                                                    SecurityOptions{cli.get("secure"), securityIdentity(service)},
                                                    ReceiveTuning{}, DiscoveryOptions{stackServices(cli), false});
  } catch (const DdsError& e) {
    cli.fail(e.what());
  }
  if (!chain_shm.empty()) {
    try {
      participant_->openChainChannel(chain_shm);
    } catch (const ChainChannelError& e) {
      cli.fail(e.what());
    }
  }
}

int ServiceContext::reportConfigOk() const {
  std::printf("%s: configuration ok\n", service_.c_str());
  return 0;
}

void ServiceContext::writeSummary(const std::string& json) const { writeSummaryFile(summary_file_, json, service_); }

void writeSummaryFile(const std::string& path, const std::string& json, const std::string& service) {
  if (path.empty()) return;
  const std::string tmp = path + ".tmp";
  bool written = false;
  {
    std::ofstream out(tmp);
    out << json << "\n";
    out.close();  // a full disk shows here, when the buffer is written
    written = !out.fail();
  }
  if (written) written = std::rename(tmp.c_str(), path.c_str()) == 0;  // never a half-written summary
  if (written) return;
  std::remove(tmp.c_str());
  // The run's result must not be lost with the file (a full disk): the supervisor reads this line instead.
  std::string line = json;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "%s: cannot write the summary %s: printing it on stdout\n", service.c_str(), path.c_str());
  std::printf("SUMMARY %s\n", line.c_str());
  std::fflush(stdout);
}

}  // namespace mft::services
