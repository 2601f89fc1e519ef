#pragma once
// The WBC stage of the chain: estimate(k) + reference(k) -> command(k) and the tick's diagnostics, with the
// scenario's controller variant.
#include <string>

#include "model/mft_polytope.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft::chain {

// The WBC configuration with the scenario's `controller` ("mft" | "sa" | "none"); throws std::invalid_argument
// naming an unknown one.
wbc::WbcConfig withScenarioController(wbc::WbcConfig config, const std::string& controller);

class WbcNode {
 public:
  // Throws like wbc::WholeBodyController's constructor.
  WbcNode(const model::RobotDescription& robot, const wbc::WbcConfig& config, const model::MftPolytope& polytope)
      : polytope_(polytope), controller_(robot, config, &polytope_) {}
  WbcNode(const WbcNode&) = delete;
  WbcNode& operator=(const WbcNode&) = delete;

  // Command and diagnostics of tick `estimate.tick` (both carry it).
  const model::ActuatorCommand& update(const model::RobotStateEstimate& estimate, const wbc::WbcReference& reference);
  const model::ActuatorCommand& command() const { return command_; }
  const wbc::WbcDiagnostics& diagnostics() const { return diag_; }
  wbc::WholeBodyController& controller() { return controller_; }
  const wbc::WholeBodyController& controller() const { return controller_; }

 private:
  model::MftPolytope polytope_;  // the controller keeps a pointer to it
  wbc::WholeBodyController controller_;
  model::ActuatorCommand command_;
  wbc::WbcDiagnostics diag_;
};

}  // namespace mft::chain
