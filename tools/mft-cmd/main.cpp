// mft-cmd: sends an operator command (height, speed, mode) or a disturbance (a sagittal push) to a running
// stack and reports the stack's verdict (docs/guide/operator-commands.md): it waits until a reader of the stack has
// matched its writer (reliable, transient local), until every service that reads the topic (the recorder included)
// has acknowledged the sample, and until the planner (commands) or the simulator (pushes) has answered on
// CommandVerdict with the command's seq.
// The exit status says what happened; nothing is reported as done that the stack did not confirm.
#include "common/tool_io.hpp"
#include "services/runtime/process.hpp"
#include "tools/mft-cmd/live_set.hpp"
#include "tools/mft-cmd/send_command.hpp"

using namespace mft;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli(
      "mft-cmd",
      "Send an operator command or a push to a running mft-wbc stack and wait for its verdict.\n"
      "  mft-cmd --domain 0 --mode step_in_place --height 0.42 --speed 0.0\n"
      "  mft-cmd --domain 0 --push 3.0 [--at 4.5 | --at-liftoff right]\n"
      "  mft-cmd --domain 0 --set wbc.weights.slack=1e5 --set wbc.gains.base_z.kp=300 [--at 20.0]\n"
      "The planner answers commands, the simulator pushes: rejected (with the reason), scheduled (a push at a\n"
      "lift-off or a later time) or applied at a tick. mft-cmd waits for 'applied' (or a rejection) up to\n"
      "--verdict-timeout; a command still only scheduled then counts as accepted. Protocol:\n"
      "docs/guide/operator-commands.md. --set changes a tunable key of config/wbc.yaml (answered by mft-wbc) or\n"
      "config/planner.yaml (mft-planner) while the stack runs, judged by that file's strict loader; a lockstep stack\n"
      "takes it at a stated simulated time only (--at), a realtime one at the next tick without --at\n"
      "(docs/guide/live-tuning.md). Several --set: one change each, in order; the exit status is the worst.\n"
      "Every service of the stack that reads the topic (the recorder too) must acknowledge the request within\n"
      "--timeout; those that did not are named.\n"
      "Exit status: 0 accepted (applied, or scheduled by the stack); 1 rejected by the stack (the reason is\n"
      "printed); 2 usage, input or DDS set-up error; 3 no stack answered on the domain within --timeout (no\n"
      "reader matched); 4 the answering service did not acknowledge the command within --timeout; 5 no verdict\n"
      "within --verdict-timeout; 6 answered as printed (applied, scheduled or rejected), but another service\n"
      "that reads the topic did not acknowledge it within --timeout (named; e.g. the recording lacks it).");
  cli.option("domain", "DDS domain id of the stack (0..232)", "0");
  cli.option("mode", "stand | step_in_place | walk (an operator command)");
  cli.option("height", "base height command [m] (the planner accepts its reachable range)", "0.42");
  cli.option("speed", "average sagittal speed command [m/s]", "0.0");
  cli.option("push", "sagittal impulse on the torso [N s], + forward (a disturbance)");
  cli.option("at", "apply the push, or the --set changes, at this simulated time [s] (0: now / the next tick)", "0");
  cli.option("at-liftoff", "apply the push at the next lift-off of this leg: right | left");
  cli.option("set", "FILE.KEY=VALUE: change a tunable key of config/FILE.yaml (wbc or planner) while the stack runs, "
             "e.g. wbc.weights.slack=1e5 or wbc.gains.swing_foot.kp=[300,300] (repeatable)");
  cli.option("seq", "sequence number of the command, echoed by its verdict (default: from the clock and pid)");
  cli.option("timeout", "seconds to wait for a reader of the stack to match, and again for every service that reads "
             "the topic to match and acknowledge", "5");
  cli.option("verdict-timeout", "seconds to wait for the stack's verdict once the command is written", "10");
  cli.flag("accepted-only", "return at the first acceptance (scheduled) instead of waiting until it is applied");
  cli.option("profiles", "DDS QoS profile file",
             mft::config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES));
  cli.option("secure", "DDS Security: the directory made by scripts/make-security.sh (secured stacks)");
  cli.option("identity", "with --secure: the identity to use", "cmd");
  cli.flag("json", "print one JSON object with the command, the verdicts and the result (also on failure)");
  cli.parse(argc, argv);

  const bool has_cmd = cli.isSet("mode"), has_push = cli.isSet("push");
  if (cli.isSet("set")) {
    if (has_cmd || has_push || cli.isSet("at-liftoff"))
      cli.fail("--set goes alone (with --at), not with --mode, --push or --at-liftoff");
    return cmd::runSet(cli);
  }
  if (has_cmd == has_push) cli.fail("give either --mode (an operator command), --push (a disturbance) or --set (a live change)");
  if (has_cmd && (cli.isSet("at") || cli.isSet("at-liftoff"))) cli.fail("--at and --at-liftoff go with --push");
  if (has_push && (cli.isSet("height") || cli.isSet("speed"))) cli.fail("--height and --speed go with --mode");
  if (cli.isSet("at") && cli.isSet("at-liftoff")) cli.fail("give --at or --at-liftoff, not both");
  return cmd::runCommand(cli);
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-cmd", [&] { return toolMain(argc, argv); });
}
