#include "services/wbc/qp_dump.hpp"

#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace mft::services {

void QpDump::declareOptions(config::CommandLine& cli) {
  cli.option("dump-qp", "write the QP of the ticks in --dump-ticks to this folder (WBCQP v1 format)");
  cli.option("dump-ticks", "comma-separated tick numbers for --dump-qp", "0");
}

QpDump::QpDump(const config::CommandLine& cli) : dir_(cli.get("dump-qp")) {
  std::stringstream ss(cli.get("dump-ticks"));
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(item.c_str(), &end, 10);
    if (*end != '\0') cli.fail("--dump-ticks: '" + item + "' is not a tick number");
    ticks_.insert(v);
  }
  if (!dir_.empty()) std::filesystem::create_directories(dir_);
}

void QpDump::afterSolve(const wbc::WholeBodyController& controller, std::uint64_t tick) const {
  if (!dir_.empty() && ticks_.count(tick) && controller.hasLastProblem())
    controller.writeLastQp(dir_ + "/wbc_" + std::to_string(tick) + ".txt");
}

}  // namespace mft::services
