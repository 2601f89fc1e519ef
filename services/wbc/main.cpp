// mft-wbc: the WBC stage of the chain (chain/wbc_node.hpp) as a service: RobotState(k) + Reference(k) -> MFT-WBC
// (Problem 1, eq. 7, safety stage) -> JointCommand(k) and WbcDiagnostics(k). It answers tick k only when it holds
// both inputs for k (docs/architecture.md#clock-and-loop-modes); the controller variant (mft, sa, none) comes from
// the scenario, everything else from config/wbc.yaml and the MFT polytope of config/mft_space.yaml (refused if it
// was made for another robot description). Live changes (mft-cmd --set wbc.<key>=<value>) apply at a tick boundary.
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "chain/wbc_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/tick_join.hpp"
#include "services/runtime/topic_io.hpp"
#include "services/wbc/qp_dump.hpp"
#include "services/wbc/wbc_summary.hpp"

using namespace mft;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-wbc", "Whole-body controller service: RobotState + Reference -> JointCommand.");
  services::ServiceContext::declareOptions(cli);
  services::QpDump::declareOptions(cli);
  cli.option("reference-max-age", "realtime: answer tick k with a Reference of tick k-N..k (takes the planner "
             "off the critical path; lockstep always needs Reference(k))", "2");
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  services::ServiceContext ctx("mft-wbc", cli);
  wbc::WbcConfig config;
  model::MftPolytope polytope;
  std::string config_text;  // the base of live changes (docs/live-tuning.md)
  try {
    config = wbc::loadWbcConfig(ctx.configFile("wbc.yaml"));
    config_text = services::configTextInForce(ctx.configFile("wbc.yaml"));
    polytope = model::loadMftPolytope(ctx.configFile("mft_space.yaml"), ctx.robot());
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  std::unique_ptr<chain::WbcNode> node;
  try {  // an unknown controller, or a configuration the controller refuses
    node = std::make_unique<chain::WbcNode>(ctx.robot(), chain::withScenarioController(config, ctx.scenario().controller),
                                            polytope);
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  const services::QpDump qp_dump(cli);

  std::mutex mutex;  // the two readers' callbacks may run on different DDS threads
  model::RobotStateEstimate state;
  wbc::WbcReference reference;
  bool have_state = false, have_reference = false;
  std::uint64_t seq = 0;
  services::TickJoin join("mft-wbc");
  services::HopTrace hops("mft-wbc", {"state_in", "reference_in", "compute", "write", "written"});
  services::WbcFigures figures;
  msg::JointCommand command_msg;
  msg::WbcDiagnostics diag_msg;
  services::TopicWriter<msg::JointCommand, msg::JointCommandPubSubType> command_writer(ctx.participant(), "JointCommand",
                                                                                       ctx.chainWriterProfile());
  services::TopicWriter<msg::WbcDiagnostics, msg::WbcDiagnosticsPubSubType> diag_writer(
      ctx.participant(), "WbcDiagnostics", ctx.chainWriterProfile());
  // Live tuning: judged here off the loop by wbc.yaml's strict loader, applied at the tick boundary in process().
  using Tuning = services::LiveTuning<wbc::WbcTuning>;
  Tuning tuning(ctx.participant(), "mft-wbc", msg::CONFIG_TARGET_WBC, msg::COMMAND_SOURCE_WBC, ctx.lockstep(),
                services::tuningStatusFile(cli.get("summary")), config_text,
                [&ctx](const std::string& text, const std::string& key, const std::string& value) {
                  auto o = wbc::applyWbcOverride(text, "wbc.yaml (live change)", key, value, ctx.robot());
                  return Tuning::Judged{wbc::tuningOf(o.config), std::move(o.yaml_text), std::move(o.value),
                                        std::move(o.previous)};
                });

  const std::uint64_t max_age = ctx.lockstep() ? 0 : static_cast<std::uint64_t>(cli.getInt("reference-max-age", 0, 50));
  // The inputs must pair before anything is sent, a repeated tick's cached answer too: a Reference already ahead
  // of a re-sent RobotState gets no answer. Only a repeated RobotState (in lockstep) gets the cached answer again,
  // not the Reference of a tick already answered: one command per tick keeps the chain's traffic minimal.
  auto process = [&](bool state_arrived) {
    if (!have_state || !have_reference) return;
    if (reference.tick > state.tick || state.tick - reference.tick > max_age) return;
    const auto action = join.decide(state.tick, true, ctx.lockstep() && state_arrived);
    if (action == services::TickJoin::Action::Resend) {
      command_writer.write(command_msg);
      diag_writer.write(diag_msg);  // a recorder that matched late must see every topic of the tick too
    }
    if (action != services::TickJoin::Action::Compute) return;
    tuning.applyDue(state.tick, state.time_s, services::toStampNs(state.time_s),
                    [&](const wbc::WbcTuning& t) { node->controller().setTuning(t); });
    hops.mark(2, state.tick);
    const model::ActuatorCommand& command = node->update(state, reference);
    const std::uint64_t stamp_ns = services::toStampNs(state.time_s);
    services::toMsg(command, stamp_ns, ++seq, &command_msg);
    command_msg.tick(state.tick);
    hops.mark(3, state.tick);
    command_writer.write(command_msg);
    hops.mark(4, state.tick);
    services::toMsg(node->diagnostics(), stamp_ns, &diag_msg);
    diag_writer.write(diag_msg);
    figures.add(node->diagnostics());
    qp_dump.afterSolve(node->controller(), state.tick);
    join.answered(state.tick);
  };
  // A non-finite input never overwrites the last good one (the safety stage would damp for as long as it comes);
  // the real sample of the same tick is still answered.
  services::TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader(
      ctx.participant(), "RobotState", ctx.chainReaderProfile(), [&](const msg::RobotState& m) {
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        bool new_clock = false;  // the controller keeps running on a new clock: nothing to restart
        if (!join.accept(services::validInput(m), "RobotState", m.tick()) || !join.admit(m.tick(), &new_clock)) return;
        services::fromMsg(m, &state);
        have_state = true;
        process(true);
      }, ctx.lockstep() ? services::ChainSlotReader::Delivery::Polled : services::ChainSlotReader::Delivery::Woken);
  // On the lockstep chain channel RobotState(k) is in its slot before the planner answers it with Reference(k):
  // the Reference takes it first, so the WBC is woken once per tick (with DDS, and in realtime where the WBC
  // answers a state with an older reference, the state comes on its own).
  services::TopicReader<msg::Reference, msg::ReferencePubSubType> reference_reader(
      ctx.participant(), "Reference", ctx.chainReaderProfile(), [&](const msg::Reference& m) {
        state_reader.pollChannel();
        hops.mark(1, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        if (!join.accept(services::validInput(m), "Reference", m.tick())) return;
        services::fromMsg(m, &reference);
        have_reference = true;
        process(false);
      });

  services::announceReady("mft-wbc");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  ctx.writeSummary(figures.summaryJson(node->controller(), join, state_reader.deadlineCounts(), tuning.summaryJson()));
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-wbc", [&] { return toolMain(argc, argv); });
}
