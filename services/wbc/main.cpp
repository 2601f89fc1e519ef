// mft-wbc: the WBC stage of the chain (chain/wbc_node.hpp) as a service: RobotState(k) + Reference(k) -> MFT-WBC
// (Problem 1, eq. 7, safety stage) -> JointCommand(k) and WbcDiagnostics(k). It answers tick k only when it holds
// both inputs for k (docs/reference/architecture.md#clock-and-loop-modes); the controller variant (mft, sa, none) comes from
// the scenario, everything else from config/wbc.yaml and the MFT polytope of config/mft_space.yaml (refused if it
// was made for another robot description). Live changes (mft-cmd --set wbc.<key>=<value>) apply at a tick
// boundary. The service's steps: services/runtime/service_main.hpp; its tick path: wbc_loop.hpp.
#include "common/tool_io.hpp"
#include "services/runtime/service_main.hpp"
#include "services/wbc/wbc_loop.hpp"

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-wbc", [&] {
    return mft::services::runService<mft::services::WbcLoop>(
        "mft-wbc", "Whole-body controller service: RobotState + Reference -> JointCommand.", argc, argv);
  });
}
