// mft-planner: the planner stage of the chain (chain/planner_node.hpp) as a service: RobotState(k) -> the paper's
// motion planner -> Reference(k). Operator commands come from the scenario (at simulated times) and from the
// OperatorCommand topic (mft-cmd, judged and answered in operator_inbox.hpp); a rejected command is reported and
// the last valid one stays in force. Live changes (mft-cmd --set planner.<key>=<value>) apply at a tick boundary.
// The service's steps: services/runtime/service_main.hpp; its tick path: planner_loop.hpp.
#include "common/tool_io.hpp"
#include "services/planner/planner_loop.hpp"
#include "services/runtime/service_main.hpp"

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-planner", [&] {
    return mft::services::runService<mft::services::PlannerLoop>(
        "mft-planner", "Motion planner service: RobotState (+ OperatorCommand) -> Reference.", argc, argv);
  });
}
