#pragma once
// `mft-sim --check-scenario FILE [--json] [--profile NAME]...`: validates a scenario and everything it names (its
// profiles, the configuration, the terrain, the initial pose as mft-sim builds it), starts nothing.
namespace mft::services {

bool isCheckScenario(int argc, char** argv);
int checkScenario(int argc, char** argv);  // 0 valid, 2 with the error

}  // namespace mft::services
