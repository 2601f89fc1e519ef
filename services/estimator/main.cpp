// mft-estimator: the estimator stage of the chain (chain/estimator_node.hpp) as a service:
// SensorData(k) [+ GroundTruth(k)] -> RobotState(k). The filter starts from the simulator's pose at the first
// tick; in the scenario's ground_truth mode it passes the simulator's truth through. The service's steps:
// services/runtime/service_main.hpp; its tick path: estimator_loop.hpp.
#include "common/tool_io.hpp"
#include "services/estimator/estimator_loop.hpp"
#include "services/runtime/service_main.hpp"

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-estimator", [&] {
    return mft::services::runService<mft::services::EstimatorLoop>(
        "mft-estimator", "State estimator service: SensorData -> RobotState.", argc, argv);
  });
}
