// mft-cyclone: a second DDS vendor on the stack's topics. Built with Eclipse Cyclone DDS from the project's own
// IDL (idl/mft_msgs.idl through Cyclone's idlc), it reads what the Fast DDS stack publishes and sends it an
// OperatorCommand, so that a test can show that another implementation interoperates with ours (wire protocol,
// type names, QoS). docs/guide/interop.md.
// Its topics and their fields come from the topic registry (idl/topics.yaml, generated mft_cyclone_topics.hpp).
#include <cmath>
#include <cstdio>
#include <cstring>

#include "cyclone_common.hpp"

static const char *const kUsage =
    "usage: mft-cyclone listen  --domain N [--topics A,B] [--seconds S] [--min-samples K] [--topic-prefix P] [--json]\n"
    "       mft-cyclone command --domain N --mode stand|step_in_place|walk --height Z [--speed V] [--wait S]\n"
    "                           [--topic-prefix P] [--json]\n"
    "\n"
    "A Cyclone DDS participant on the mft-wbc topics (docs/guide/interop.md), built from idl/mft_msgs.idl.\n"
    "listen : reads --topics (default SensorData,JointCommand,Reference; any topic of idl/topics.yaml) for\n"
    "         --seconds (default 3) or until each topic has --min-samples samples; prints per topic: samples,\n"
    "         first/last tick (an event's seq), tick decreases, non-finite values, and the range of one value\n"
    "         (joint positions, torques, reference height; else the first floating-point field). Exit 3 if a\n"
    "         topic is silent.\n"
    "command: sends one OperatorCommand (reliable, transient-local, as mft-cmd does) and waits --wait seconds\n"
    "         (default 10) for the planner's CommandVerdict with its seq. Exit 0 applied, 1 rejected, 5 none.\n"
    "Topics are named as ROS 2 names them, --topic-prefix (default rt/mft/) + snake_case type name; types\n"
    "mft::msg::dds_::<Name>_. Only loopback is used (Cyclone's lo interface with multicast discovery).\n";

int main(int argc, char **argv) {
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? EXIT_USAGE : EXIT_OK;
  }
  const char *sub = argv[1];
  const bool listen = !strcmp(sub, "listen"), command = !strcmp(sub, "command");
  if (!listen && !command) return usage_error("the first argument must be listen or command");
  double domain = -1, seconds = 3, min_samples = 0, height = std::nan(""), speed = 0, wait_s = 10;
  int mode = -1;
  const char *prefix = "rt/mft/";
  const char *topics = "SensorData,JointCommand,Reference";
  bool json = false;
  for (int i = 2; i < argc; ++i) {
    const char *a = argv[i];
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(a, "--help")) {
      fputs(kUsage, stdout);
      return EXIT_OK;
    } else if (!strcmp(a, "--json")) {
      json = true;
      continue;
    }
    if (!v) return usage_error("an option without its value");
    ++i;
    if (!strcmp(a, "--domain")) {
      if (!parse_double(v, 0, 232, &domain) || domain != std::floor(domain)) return usage_error("--domain: 0..232");
    } else if (!strcmp(a, "--seconds") && listen) {
      if (!parse_double(v, 0.1, 3600, &seconds)) return usage_error("--seconds: 0.1..3600");
    } else if (!strcmp(a, "--min-samples") && listen) {
      if (!parse_double(v, 0, 1e9, &min_samples)) return usage_error("--min-samples: 0..1e9");
    } else if (!strcmp(a, "--topics") && listen) {
      if (strlen(v) > 1000) return usage_error("--topics: at most 1000 characters");
      topics = v;
    } else if (!strcmp(a, "--topic-prefix")) {
      if (strlen(v) > 64) return usage_error("--topic-prefix: at most 64 characters");
      prefix = v;
    } else if (!strcmp(a, "--mode") && command) {
      if (!strcmp(v, "stand")) mode = mft_msg_LOCOMOTION_STAND;
      else if (!strcmp(v, "step_in_place")) mode = mft_msg_LOCOMOTION_STEP_IN_PLACE;
      else if (!strcmp(v, "walk")) mode = mft_msg_LOCOMOTION_WALK;
      else return usage_error("--mode: stand, step_in_place or walk");
    } else if (!strcmp(a, "--height") && command) {
      if (!parse_double(v, 0, 2, &height)) return usage_error("--height: 0..2 m");
    } else if (!strcmp(a, "--speed") && command) {
      if (!parse_double(v, -5, 5, &speed)) return usage_error("--speed: -5..5 m/s");
    } else if (!strcmp(a, "--wait") && command) {
      if (!parse_double(v, 0.1, 600, &wait_s)) return usage_error("--wait: 0.1..600 s");
    } else {
      char msg[160];
      snprintf(msg, sizeof msg, "unknown option %s for %s", a, sub);
      return usage_error(msg);
    }
  }
  if (domain < 0) return usage_error("--domain is required");
  if (listen) return cmd_listen((int)domain, seconds, (long)min_samples, prefix, topics, json);
  if (mode < 0 || !std::isfinite(height)) return usage_error("command needs --mode and --height");
  return cmd_command((int)domain, mode, height, speed, wait_s, prefix, json);
}
