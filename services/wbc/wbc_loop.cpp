#include "services/wbc/wbc_loop.hpp"

#include "common/strict_yaml.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"

namespace mft::services {

void WbcLoop::declareOptions(CommandLine& cli) {
  QpDump::declareOptions(cli);
  cli.option("reference-max-age", "realtime: answer tick k with a Reference of tick k-N..k (takes the planner "
             "off the critical path; lockstep always needs Reference(k))", "2");
}

TunableNode<chain::WbcNode> WbcLoop::load(const ServiceContext& ctx, const CommandLine& cli) {
  wbc::WbcConfig config;
  model::MftPolytope polytope;
  TunableNode<chain::WbcNode> loaded;
  try {
    config = wbc::loadWbcConfig(ctx.configFile("wbc.yaml"));
    loaded.config_text = configTextInForce(ctx.configFile("wbc.yaml"));
    polytope = model::loadMftPolytope(ctx.configFile("mft_space.yaml"), ctx.robot());
  } catch (const config::ConfigError& e) {
    cli.fail(e.what());
  }
  try {
    loaded.node = std::make_unique<chain::WbcNode>(
        ctx.robot(), chain::withScenarioController(config, ctx.scenario().controller), polytope);
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  return loaded;
}

// Live tuning: judged off the loop by wbc.yaml's strict loader, applied at the tick boundary in answer().
// On the lockstep chain channel RobotState(k) is in its slot before the planner answers it with Reference(k): the
// Reference takes it first, so the WBC is woken once per tick (with DDS, and in realtime where the WBC answers a
// state with an older reference, the state comes on its own).
WbcLoop::WbcLoop(ServiceContext& ctx, const CommandLine& cli, const TunableNode<chain::WbcNode>& loaded)
    : ctx_(ctx),
      node_(*loaded.node),
      qp_dump_(cli),
      command_writer_(ctx.writing("JointCommand")),
      diag_writer_(ctx.writing("WbcDiagnostics")),
      tuning_(ctx.participant(), "mft-wbc", msg::CONFIG_TARGET_WBC, msg::COMMAND_SOURCE_WBC, ctx.lockstep(),
              tuningStatusFile(cli.get("summary")), loaded.config_text,
              [&ctx](const std::string& text, const std::string& key, const std::string& value) {
                auto o = wbc::applyWbcOverride(text, "wbc.yaml (live change)", key, value, ctx.robot());
                return LiveTuning<wbc::WbcTuning>::Judged{wbc::tuningOf(o.config), std::move(o.yaml_text),
                                                        std::move(o.value), std::move(o.previous)};
              }),
      max_age_(ctx.lockstep() ? 0 : static_cast<std::uint64_t>(cli.getInt("reference-max-age", 0, 50))),
      state_reader_(ctx.reading("RobotState"),
                    [this](const msg::RobotState& m) { onState(m); },
                    ctx.lockstep() ? ChainSlotReader::Delivery::Polled : ChainSlotReader::Delivery::Woken),
      reference_reader_(ctx.reading("Reference"),
                        [this](const msg::Reference& m) { onReference(m); }) {}

// A non-finite input never overwrites the last good one (the safety stage would damp for as long as it comes);
// the real sample of the same tick is still answered.
void WbcLoop::onState(const msg::RobotState& m) {
  hops_.mark(0, m.tick());
  std::lock_guard<std::mutex> lock(mutex_);
  // On a new clock (a restarted simulator) the controller keeps running: nothing to restart.
  if (state_.takeTick(join_, m, "RobotState")) process(true);
}

void WbcLoop::onReference(const msg::Reference& m) {
  state_reader_.pollChannel();
  hops_.mark(1, m.tick());
  std::lock_guard<std::mutex> lock(mutex_);
  if (reference_.take(join_, m, "Reference")) process(false);
}

// The inputs must pair before anything is sent, a repeated tick's cached answer too: a Reference already ahead of
// a re-sent RobotState gets no answer. Only a repeated RobotState (in lockstep) gets the cached answer again, not
// the Reference of a tick already answered: one command per tick keeps the chain's traffic minimal.
void WbcLoop::process(bool state_arrived) {
  if (!state_.have || !reference_.have) return;
  const std::uint64_t tick = state_.value.tick, reference_tick = reference_.value.tick;
  if (reference_tick > tick || tick - reference_tick > max_age_) return;
  const auto action = join_.decide(tick, true, ctx_.lockstep() && state_arrived);
  if (action == TickJoin::Action::Resend) {
    command_writer_.write(command_msg_);
    diag_writer_.write(diag_msg_);  // a recorder that matched late must see every topic of the tick too
  }
  if (action == TickJoin::Action::Compute) answer();
}

void WbcLoop::answer() {
  const model::RobotStateEstimate& state = state_.value;
  tuning_.applyDue(state.tick, state.time_s, toStampNs(state.time_s),
                   [&](const wbc::WbcTuning& t) { node_.controller().setTuning(t); });
  hops_.mark(2, state.tick);
  const model::ActuatorCommand& command = node_.update(state, reference_.value);
  const std::uint64_t stamp_ns = toStampNs(state.time_s);
  toMsg(command, stamp_ns, ++seq_, &command_msg_);
  command_msg_.tick(state.tick);
  hops_.mark(3, state.tick);
  command_writer_.write(command_msg_);
  hops_.mark(4, state.tick);
  toMsg(node_.diagnostics(), stamp_ns, &diag_msg_);
  diag_writer_.write(diag_msg_);
  figures_.add(node_.diagnostics());
  qp_dump_.afterSolve(node_.controller(), state.tick);
  join_.answered(state.tick);
}

std::string WbcLoop::summaryJson() {
  std::lock_guard<std::mutex> lock(mutex_);
  return figures_.summaryJson(node_.controller(), join_, state_reader_.deadlineCounts(), tuning_.summaryJson());
}

}  // namespace mft::services
