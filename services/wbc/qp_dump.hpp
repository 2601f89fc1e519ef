#pragma once
// mft-wbc --dump-qp DIR --dump-ticks K1,K2,...: the QP of chosen ticks written to files (WBCQP v1), so that one
// solve of a running stack can be studied offline (tools/mft-qp). Off unless --dump-qp is given.
#include <cstdint>
#include <set>
#include <string>

#include "common/command_line.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft::services {

class QpDump {
 public:
  static void declareOptions(config::CommandLine& cli);
  // Reads the options of a parsed command line (cli.fail() on a tick that is not a number); creates DIR.
  explicit QpDump(const config::CommandLine& cli);
  // After the solve of `tick`: writes DIR/wbc_<tick>.txt when the tick is one of --dump-ticks.
  void afterSolve(const wbc::WholeBodyController& controller, std::uint64_t tick) const;

 private:
  std::string dir_;
  std::set<std::uint64_t> ticks_;
};

}  // namespace mft::services
