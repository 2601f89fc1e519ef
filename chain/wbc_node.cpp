#include "chain/wbc_node.hpp"

#include <stdexcept>

namespace mft::chain {

wbc::WbcConfig withScenarioController(wbc::WbcConfig config, const std::string& controller) {
  if (!wbc::parseVariant(controller, &config.variant))
    throw std::invalid_argument("unknown controller '" + controller + "'");
  return config;
}

const model::ActuatorCommand& WbcNode::update(const model::RobotStateEstimate& estimate,
                                              const wbc::WbcReference& reference) {
  command_ = controller_.update(estimate, reference, &diag_);
  command_.tick = estimate.tick;
  diag_.tick = estimate.tick;
  return command_;
}

}  // namespace mft::chain
