// mft-cmd: sends an operator command (height, speed, mode) or a disturbance (a sagittal push) to a running
// stack, and waits until the planner (or the simulator) has matched it, so nothing is sent into the void.
#include <chrono>
#include <cstdio>
#include <string>

#include "MftMsgs.h"
#include "MftMsgsPubSubTypes.h"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/process.hpp"
#include "services/runtime/topic_io.hpp"
#include "model/config/tool_io.hpp"

using namespace mft;
using namespace std::chrono_literals;

static int toolMain(int argc, char** argv) {
  services::CommandLine cli(
      "mft-cmd",
      "Send an operator command or a push to a running mft-wbc stack.\n"
      "  mft-cmd --domain 0 --mode step_in_place --height 0.42 --speed 0.0\n"
      "  mft-cmd --domain 0 --push 3.0 [--at 4.5 | --at-liftoff right]");
  cli.option("domain", "DDS domain id of the stack (0..232)", "0");
  cli.option("mode", "stand | step_in_place | walk (an operator command)");
  cli.option("height", "base height command [m]", "0.42");
  cli.option("speed", "average sagittal speed command [m/s]", "0.0");
  cli.option("push", "sagittal impulse on the torso [N s], + forward (a disturbance)");
  cli.option("at", "apply the push at this simulated time [s] (default: now)", "0");
  cli.option("at-liftoff", "apply the push at the next lift-off of this leg: right | left");
  cli.option("seq", "sequence number of the message (default: wall-clock based)");
  cli.option("timeout", "seconds to wait for the stack to match", "5");
  cli.option("profiles", "DDS QoS profile file", MFT_DDS_PROFILES);
  cli.option("secure", "DDS Security: the directory made by scripts/make-security.sh (secured stacks)");
  cli.option("identity", "with --secure: the identity to use", "cmd");
  cli.flag("json", "print what was sent as JSON");
  cli.parse(argc, argv);

  const bool has_cmd = cli.isSet("mode"), has_push = cli.isSet("push");
  if (has_cmd == has_push) cli.fail("give either --mode (an operator command) or --push (a disturbance)");
  const auto seq = cli.isSet("seq")
                       ? static_cast<unsigned long long>(cli.getInt("seq", 0, 1L << 62))
                       : static_cast<unsigned long long>(
                             std::chrono::system_clock::now().time_since_epoch() / std::chrono::milliseconds(1));
  const auto timeout = std::chrono::milliseconds(static_cast<long>(cli.getDouble("timeout", 0.1, 600) * 1000));
  try {
    services::DdsParticipant participant(static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId)),
                                         cli.get("profiles"), "mft-cmd",
                                         services::SecurityOptions{cli.get("secure"), cli.get("identity")});
    if (has_cmd) {
      msg::OperatorCommand m;
      const std::string mode = cli.get("mode");
      if (mode == "stand") m.mode(msg::LOCOMOTION_STAND);
      else if (mode == "step_in_place") m.mode(msg::LOCOMOTION_STEP_IN_PLACE);
      else if (mode == "walk") m.mode(msg::LOCOMOTION_WALK);
      else cli.fail("--mode: unknown mode '" + mode + "' (stand, step_in_place or walk)");
      m.seq(seq);
      m.z_cmd(cli.getDouble("height", 0.0, 2.0));
      m.v_cmd(cli.getDouble("speed", -5.0, 5.0));
      services::TopicWriter<msg::OperatorCommand, msg::OperatorCommandPubSubType> w(participant, "OperatorCommand",
                                                                                      "event_writer");
      if (!services::waitUntil([&] { return w.matched() > 0; }, timeout)) {
        std::fprintf(stderr, "mft-cmd: no planner on domain %ld answered within the timeout\n", cli.getInt("domain", 0, 232));
        return 1;
      }
      w.write(m);
      if (cli.isSet("json"))
        std::printf("{\"sent\": \"OperatorCommand\", \"seq\": %llu, \"mode\": \"%s\", \"z_cmd\": %.6g, \"v_cmd\": %.6g}\n",
                    seq, mode.c_str(), m.z_cmd(), m.v_cmd());
      else
        std::printf("sent OperatorCommand seq %llu: %s, height %.3f m, speed %.3f m/s\n", seq, mode.c_str(), m.z_cmd(), m.v_cmd());
    } else {
      msg::Disturbance d;
      d.seq(seq);
      d.impulse_Ns(cli.getDouble("push", -200.0, 200.0));
      d.time_s(cli.getDouble("at", 0.0, 1e6));
      d.trigger(msg::TRIGGER_AT_TIME);
      d.leg(-1);
      if (cli.isSet("at-liftoff")) {
        const std::string leg = cli.get("at-liftoff");
        if (leg != "right" && leg != "left") cli.fail("--at-liftoff: expected right or left");
        d.trigger(msg::TRIGGER_AT_NEXT_LIFTOFF);
        d.leg(static_cast<std::int16_t>(leg == "right" ? 0 : 1));
      }
      services::TopicWriter<msg::Disturbance, msg::DisturbancePubSubType> w(participant, "Disturbance", "event_writer");
      if (!services::waitUntil([&] { return w.matched() > 0; }, timeout)) {
        std::fprintf(stderr, "mft-cmd: no simulator on domain %ld answered within the timeout\n", cli.getInt("domain", 0, 232));
        return 1;
      }
      w.write(d);
      if (cli.isSet("json"))
        std::printf("{\"sent\": \"Disturbance\", \"seq\": %llu, \"impulse_Ns\": %.6g, \"trigger\": \"%s\", \"time_s\": %.6g, \"leg\": %d}\n",
                    seq, d.impulse_Ns(), d.trigger() == msg::TRIGGER_AT_TIME ? "at_time" : "at_next_liftoff", d.time_s(), d.leg());
      else
        std::printf("sent Disturbance seq %llu: %.3f N s %s\n", seq, d.impulse_Ns(),
                    d.trigger() == msg::TRIGGER_AT_TIME ? "at time" : "at next lift-off");
    }
    // Reliable transient-local writers: give the reader a moment to acknowledge before the process ends.
    std::this_thread::sleep_for(200ms);
  } catch (const services::DdsError& e) {
    std::fprintf(stderr, "mft-cmd: %s\n", e.what());
    return 2;
  }
  return 0;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-cmd", [&] { return toolMain(argc, argv); });
}
