#pragma once
// What every service main starts with: the common options of the service contract (see
// services/mft-supervisor), the robot description, the scenario, the DDS participant, the endpoints' QoS profiles
// (from the topic registry and the loop mode), and the JSON summary written at exit.
#include <memory>
#include <string>
#include <vector>

#include "model/robot_description.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/runtime/topic_qos.hpp"
#include "chain/scenario.hpp"

namespace mft::services {

enum class LoopMode { Lockstep, Realtime };

class ServiceContext {
 public:
  // Declares the common options on `cli`; call before cli.parse().
  static void declareOptions(CommandLine& cli);
  // The DDS profile file of a parsed command line: --profiles, else dds_profiles.xml of --config-dir.
  static std::string profilesFile(const CommandLine& cli);
  // --stack-services, checked (cli.fail on anything but names and commas); "" when not given.
  static std::string stackServices(const CommandLine& cli);
  // After cli.parse(): loads the configuration and creates the participant. Exits 2 with a clear message on
  // any configuration error (nothing is started). With --check-config it creates no participant but checks
  // the DDS profile file with Fast DDS's XML loader instead.
  ServiceContext(const std::string& service, const CommandLine& cli);

  // --check-config: the main loads its own configuration files with their strict loaders, then, instead of
  // creating its endpoints, returns reportConfigOk() (prints "<service>: configuration ok", exit status 0).
  // Errors exit 2 through cli.fail() as always. The supervisor runs this for every service before it starts any.
  bool checkOnly() const { return check_only_; }
  int reportConfigOk() const;

  const std::string& service() const { return service_; }
  LoopMode mode() const { return mode_; }
  bool lockstep() const { return mode_ == LoopMode::Lockstep; }
  const model::RobotDescription& robot() const { return robot_; }
  const chain::Scenario& scenario() const { return scenario_; }
  // The configuration profiles in force (the scenario's, then --profile), already applied to every loader.
  const std::vector<std::string>& profileNames() const { return profile_names_; }
  std::string configFile(const std::string& name) const { return config_dir_ + "/" + name; }
  DdsParticipant& participant() { return *participant_; }

  // This service's writer or reader on `topic`, with the QoS profile of the topic's row in the registry and the
  // loop mode (topic_qos.hpp): the 1 kHz chain's is reliable in lockstep (every tick must arrive),
  // deadline-watched best effort in realtime.
  TopicEndpoint writing(const std::string& topic) { return {participant(), topic, serviceWriterProfile(topic, lockstep())}; }
  TopicEndpoint reading(const std::string& topic) { return {participant(), topic, serviceReaderProfile(topic, lockstep())}; }

  // Writes `json` (an object) to the --summary file, if one was given. Never throws.
  void writeSummary(const std::string& json) const;

 private:
  std::string service_;
  bool check_only_ = false;
  LoopMode mode_ = LoopMode::Lockstep;
  std::string config_dir_;
  std::string summary_file_;
  model::RobotDescription robot_;
  chain::Scenario scenario_;
  std::vector<std::string> profile_names_;
  std::unique_ptr<DdsParticipant> participant_;
};

// Writes `json` to `path` (never half-written). When that fails (a full disk), prints it on stdout as one line
// "SUMMARY {...}", which the supervisor reads from the service's output instead. Never throws.
void writeSummaryFile(const std::string& path, const std::string& json, const std::string& service);

}  // namespace mft::services
