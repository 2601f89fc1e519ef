// mft-sim: the simulator stage of the chain (chain/sim_node.hpp) as a service. It owns the clock
// (docs/reference/architecture.md#clock-and-loop-modes):
//  lockstep: publish GroundTruth(k) and SensorData(k), wait for JointCommand(k), step; deterministic, as fast
//            as the chain answers; a missing answer is a named timeout error (exit status 3).
//  realtime: step on the wall clock at 1 kHz, hold the newest command; the actuator driver
//            (chain/actuator_driver.hpp) damps when commands stop, and resumes when they come back.
// It plays the scenario's pushes and the Disturbance topic's (topic_pushes.hpp), ends the run at the scenario's
// duration (or at a fall), and writes the run summary (sim_summary.hpp). The service's steps:
// services/runtime/service_main.hpp; its run: sim_loop.hpp.
#include "common/tool_io.hpp"
#include "services/runtime/service_main.hpp"
#include "services/sim/check_scenario.hpp"
#include "services/sim/sim_loop.hpp"

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-sim", [&] {
    if (mft::services::isCheckScenario(argc, argv)) return mft::services::checkScenario(argc, argv);
    return mft::services::runService<mft::services::SimLoop>(
        "mft-sim",
        "ODE simulator service: owns the clock; JointCommand -> SensorData, GroundTruth.\n"
        "Also: mft-sim --check-scenario FILE [--json] validates a scenario and exits.",
        argc, argv);
  });
}
