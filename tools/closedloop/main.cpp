// mft-closedloop: the whole controller chain (sim, estimator, planner, WBC) in one process on the sim clock.
// A bench for tuning, tests and plots; the product path is the DDS stack in services/.
//
//   mft-closedloop --scenario config/scenarios/demo.yaml --json
//   mft-closedloop --height 0.44 --controller sa --duration 20 --csv /tmp/step.csv
//   mft-closedloop --speed 0.3 --duration 20 --estimator ground_truth
//   mft-closedloop --stand --height 0.40 --duration 2 --dump-qp tests/data/qp --dump-from 1.5 --dump-count 20
#include <cstdio>
#include <memory>

#include "chain/closed_loop.hpp"
#include "common/command_line.hpp"
#include "common/tool_io.hpp"
#include "tools/closedloop/closed_loop_cli.hpp"

using namespace mft;

static int toolMain(int argc, char** argv) {
  config::CommandLine cli(
      "mft-closedloop",
      "Run sim -> estimator -> planner -> WBC in one process on the sim clock, with the stack's configs, reference\n"
      "mapping and fall criteria. Without --scenario: stand at --height until --step-at, then step in place\n"
      "(--speed 0) or walk (--speed != 0). With --scenario the given options override the file's values.");
  closedloop::declareOptions(cli);
  cli.parse(argc, argv);

  closedloop::Configs configs;
  const chain::Scenario scenario = closedloop::scenarioFromOptions(cli, &configs);
  closedloop::RunOptions options;
  options.stop_at_fall = !cli.isSet("continue-after-fall");
  options.stats_from_s = cli.getDouble("stats-from", 0.0, 3600.0);
  std::unique_ptr<closedloop::ClosedLoop> loop;
  try {
    loop = std::make_unique<closedloop::ClosedLoop>(configs, scenario, options);
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  closedloop::TickOutputs outputs(cli, configs);
  const auto& s = loop->run([&](const closedloop::ClosedLoop& l) { outputs.onTick(l); });
  outputs.finish(cli);

  if (cli.isSet("json")) {
    config::JsonWriter w;
    w.beginObject().key("scenario").raw(scenario.toJson()).key("summary").raw(s.toJson());
    w.key("recovery").raw(loop->recoveryJson());
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    closedloop::printTextSummary(scenario, s, *loop, options.stats_from_s);
  }
  return s.fell ? 1 : 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-closedloop", [&] { return toolMain(argc, argv); });
}
