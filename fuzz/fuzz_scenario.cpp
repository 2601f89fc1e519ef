// Fuzz target: the scenario loader (chain/scenario.cpp), as `mft-sim --check-scenario` and the supervisor read a
// scenario file, then what a run does next with it: its JSON summary and the profiles it names, loaded from
// config/profiles/. Either accepted, or config::ConfigError naming the input (or the profile file it names).
#include "chain/scenario.hpp"
#include "common/profiles.hpp"
#include "common/strict_yaml.hpp"
#include "fuzz/fuzz_target.hpp"

namespace mft::fuzz {

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  const std::string origin = "fuzz-input";
  chain::Scenario s;
  try {
    s = chain::parseScenario(bytesText(data, size), origin);
  } catch (const config::ConfigError& e) {
    return refusedWith(e.what(), origin);
  }
  const std::string json = s.toJson();
  const std::vector<std::string> profiles = chain::runProfiles(s, {});
  try {
    config::ProfileSet::load(MFT_CONFIG_DIR, profiles);
  } catch (const config::ConfigError& e) {
    return refusedWith(e.what(), "profile");
  }
  return acceptedAs("scenario '" + s.name + "', " + std::to_string(s.commands.size()) + " commands, " +
                    std::to_string(s.pushes.size()) + " pushes, " + std::to_string(json.size()) + " bytes of JSON");
}

}  // namespace mft::fuzz
