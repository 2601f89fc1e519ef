// mft-wbc: RobotState(k) + Reference(k) -> MFT-WBC (Problem 1, eq. 7, safety stage) -> JointCommand(k) and
// WbcDiagnostics(k). It answers tick k only when it holds both inputs for k (docs/architecture.md#clock-and-loop-modes); the
// controller variant (mft, sa, none) comes from the scenario, everything else from config/wbc.yaml and the
// MFT polytope of config/mft_space.yaml (refused if it was made for another robot description).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "idl/msg_pubsub.hpp"
#include "model/config/strict_yaml.hpp"
#include "model/mft_polytope.hpp"
#include "services/runtime/convert.hpp"
#include "services/runtime/hop_trace.hpp"
#include "services/runtime/latency_stats.hpp"
#include "services/runtime/live_tuning.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/tick_gate.hpp"
#include "services/runtime/service_context.hpp"
#include "services/runtime/topic_io.hpp"
#include "wbc/whole_body_controller.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;

namespace {
std::set<std::uint64_t> parseTicks(const std::string& text, const services::CommandLine& cli) {
  std::set<std::uint64_t> ticks;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(item.c_str(), &end, 10);
    if (*end != '\0') cli.fail("--dump-ticks: '" + item + "' is not a tick number");
    ticks.insert(v);
  }
  return ticks;
}

void toMsg(const wbc::WbcDiagnostics& d, std::uint64_t stamp_ns, msg::WbcDiagnostics* m) {
  m->tick(d.tick);
  m->stamp_ns(stamp_ns);
  m->solve_time_us(d.solve_time_us);
  m->tick_time_us(d.tick_time_us);
  m->iterations(d.iterations);
  m->status(static_cast<std::int32_t>(d.status));
  m->active_constraints(d.active_constraints);
  m->slack_norm(d.slack_norm);
  m->task_error(d.task_error);
  m->lti(d.lti);
  m->raci(d.raci);
  m->safety_events(d.safety.events);
  m->holding(d.safety_mode == wbc::SafetyMode::Holding);
  m->damping(d.safety_mode == wbc::SafetyMode::Damping);
}
}  // namespace

static int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-wbc", "Whole-body controller service: RobotState + Reference -> JointCommand.");
  services::ServiceContext::declareOptions(cli);
  cli.option("dump-qp", "write the QP of the ticks in --dump-ticks to this folder (WBCQP v1 format)");
  cli.option("dump-ticks", "comma-separated tick numbers for --dump-qp", "0");
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
  if (!wbc::parseVariant(ctx.scenario().controller, &config.variant))
    cli.fail("unknown controller '" + ctx.scenario().controller + "'");
  std::unique_ptr<wbc::WholeBodyController> controller_ptr;
  try {
    controller_ptr = std::make_unique<wbc::WholeBodyController>(ctx.robot(), config, &polytope);
  } catch (const std::exception& e) {
    cli.fail(e.what());
  }
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  wbc::WholeBodyController& controller = *controller_ptr;
  const std::string dump_dir = cli.get("dump-qp");
  const auto dump_ticks = parseTicks(cli.get("dump-ticks"), cli);
  if (!dump_dir.empty()) std::filesystem::create_directories(dump_dir);

  std::mutex mutex;
  model::RobotStateEstimate state;
  wbc::WbcReference reference;
  bool have_state = false, have_reference = false, answered = false;
  std::uint64_t last_tick = 0, seq = 0, ticks = 0, non_optimal = 0, refused_inputs = 0;
  services::HopTrace hops("mft-wbc", {"state_in", "reference_in", "compute", "write", "written"});
  services::TickGate gate;  // refuses a stray far tick, follows a restarted simulator (tick_gate.hpp)
  int max_iterations = 0;
  msg::JointCommand command_msg;
  msg::WbcDiagnostics diag_msg;
  wbc::WbcDiagnostics diag;
  services::LatencyStats solve_us, tick_us;

  services::TopicWriter<msg::JointCommand, msg::JointCommandPubSubType> command_writer(ctx.participant(), "JointCommand",
                                                                                       ctx.chainWriterProfile());
  services::TopicWriter<msg::WbcDiagnostics, msg::WbcDiagnosticsPubSubType> diag_writer(
      ctx.participant(), "WbcDiagnostics", ctx.chainWriterProfile());

  // Live tuning (mft-cmd --set wbc.<key>=<value>): judged here off the loop by wbc.yaml's strict loader, applied
  // at the tick boundary in process().
  using Tuning = services::LiveTuning<wbc::WbcTuning>;
  Tuning tuning(ctx.participant(), "mft-wbc", msg::CONFIG_TARGET_WBC, msg::COMMAND_SOURCE_WBC, ctx.lockstep(),
                services::tuningStatusFile(cli.get("summary")), config_text,
                [&ctx](const std::string& text, const std::string& key, const std::string& value) {
                  auto o = wbc::applyWbcOverride(text, "wbc.yaml (live change)", key, value, ctx.robot());
                  return Tuning::Judged{wbc::tuningOf(o.config), std::move(o.yaml_text), std::move(o.value),
                                        std::move(o.previous)};
                });

  const std::uint64_t max_age = ctx.lockstep() ? 0 : static_cast<std::uint64_t>(cli.getInt("reference-max-age", 0, 50));
  // Only a repeated RobotState (a re-sent tick) gets the cached answer again, not the Reference of a tick
  // already answered: one command per tick keeps the lockstep chain's traffic minimal.
  auto process = [&](bool state_arrived) {
    if (!have_state || !have_reference) return;
    if (reference.tick > state.tick || state.tick - reference.tick > max_age) return;
    if (answered && state.tick == last_tick) {
      if (ctx.lockstep() && state_arrived) {  // a repeated tick, same answer
        command_writer.write(command_msg);
        diag_writer.write(diag_msg);  // a recorder that matched late must see every topic of the tick too
      }
      return;
    }
    if (answered && state.tick < last_tick) return;
    tuning.applyDue(state.tick, state.time_s, services::toStampNs(state.time_s),
                    [&](const wbc::WbcTuning& t) { controller.setTuning(t); });
    hops.mark(2, state.tick);
    const model::ActuatorCommand command = controller.update(state, reference, &diag);
    diag.tick = state.tick;
    const std::uint64_t stamp_ns = services::toStampNs(state.time_s);
    services::toMsg(command, stamp_ns, ++seq, &command_msg);
    command_msg.tick(state.tick);
    hops.mark(3, state.tick);
    command_writer.write(command_msg);
    hops.mark(4, state.tick);
    toMsg(diag, stamp_ns, &diag_msg);
    diag_writer.write(diag_msg);
    solve_us.add(diag.solve_time_us);
    tick_us.add(diag.tick_time_us);
    if (diag.status != qp::QpStatus::Optimal) ++non_optimal;
    max_iterations = std::max(max_iterations, diag.iterations);
    if (!dump_dir.empty() && dump_ticks.count(state.tick) && controller.hasLastProblem())
      controller.writeLastQp(dump_dir + "/wbc_" + std::to_string(state.tick) + ".txt");
    last_tick = state.tick;
    gate.answered(last_tick);
    answered = true;
    ++ticks;
  };
  services::TopicReader<msg::RobotState, msg::RobotStatePubSubType> state_reader(
      ctx.participant(), "RobotState", ctx.chainReaderProfile(), [&](const msg::RobotState& m) {
        hops.mark(0, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        // A non-finite input never overwrites the last good one (the safety stage would damp for as long as
        // it comes); the real sample of the same tick is still answered.
        if (!services::validInput(m)) {
          if (refused_inputs++ == 0) std::printf("mft-wbc: refused a non-finite or implausible RobotState (tick %llu)\n", static_cast<unsigned long long>(m.tick()));
          return;
        }
        const auto decision = gate.check(m.tick());
        if (decision == services::TickGate::Decision::Refused) return;
        if (decision == services::TickGate::Decision::NewClock) {
          std::printf("mft-wbc: the simulator's clock restarted (tick %llu after %llu)\n",
                      static_cast<unsigned long long>(m.tick()), static_cast<unsigned long long>(last_tick));
          answered = false;
        }
        services::fromMsg(m, &state);
        have_state = true;
        process(true);
      });
  services::TopicReader<msg::Reference, msg::ReferencePubSubType> reference_reader(
      ctx.participant(), "Reference", ctx.chainReaderProfile(), [&](const msg::Reference& m) {
        hops.mark(1, m.tick());
        std::lock_guard<std::mutex> lock(mutex);
        if (!services::validInput(m)) {
          if (refused_inputs++ == 0) std::printf("mft-wbc: refused a non-finite or implausible Reference (tick %llu)\n", static_cast<unsigned long long>(m.tick()));
          return;
        }
        services::fromMsg(m, &reference);
        have_reference = true;
        process(false);
      });

  services::announceReady("mft-wbc");
  while (!services::shutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));

  std::lock_guard<std::mutex> lock(mutex);
  const auto& s = controller.safety().counters();
  char buf[900];
  std::snprintf(buf, sizeof buf,
                "{\"service\": \"mft-wbc\", \"variant\": \"%s\", \"ticks\": %llu, \"last_tick\": %llu, "
                "\"non_optimal_solves\": %llu, \"max_iterations\": %d, \"safety_events\": %llu, "
                "\"safety\": {\"nonfinite_input\": %llu, \"model_failure\": %llu, \"solver_failure\": %llu, "
                "\"nonfinite_output\": %llu, \"hold_ticks\": %llu, \"damping_ticks\": %llu}, "
                "\"refused_inputs\": %llu, \"refused_ticks\": %llu, \"new_clocks\": %llu, \"deadline_misses\": %llu, ",
                wbc::toString(controller.variant()), static_cast<unsigned long long>(ticks),
                static_cast<unsigned long long>(last_tick), static_cast<unsigned long long>(non_optimal), max_iterations,
                static_cast<unsigned long long>(s.events), static_cast<unsigned long long>(s.nonfinite_input),
                static_cast<unsigned long long>(s.model_failure), static_cast<unsigned long long>(s.solver_failure),
                static_cast<unsigned long long>(s.nonfinite_output), static_cast<unsigned long long>(s.hold_ticks),
                static_cast<unsigned long long>(s.damping_ticks), static_cast<unsigned long long>(refused_inputs),
                static_cast<unsigned long long>(gate.refused()), static_cast<unsigned long long>(gate.newClocks()),
                static_cast<unsigned long long>(state_reader.requestedDeadlineMisses()));
  ctx.writeSummary(std::string(buf) + "\"solve_time_us\": " + solve_us.json() + ", \"tick_time_us\": " + tick_us.json() +
                   ", \"live_changes\": " + tuning.summaryJson() + "}");
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-wbc", [&] { return toolMain(argc, argv); });
}
