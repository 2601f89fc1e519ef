// mft-cyclone: a second DDS vendor on the stack's topics. Built with Eclipse Cyclone DDS from the project's own
// IDL (idl/mft_msgs.idl through Cyclone's idlc), it reads what the Fast DDS stack publishes and sends it an
// OperatorCommand, so that a test can show that another implementation interoperates with ours (wire protocol,
// type names, QoS). docs/interop.md.
#include <dds/dds.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

extern "C" {
#include "mft_msgs.h"
}

enum { EXIT_OK = 0, EXIT_REJECTED = 1, EXIT_USAGE = 2, EXIT_NO_DATA = 3, EXIT_NO_VERDICT = 5 };

static const char *const kUsage =
    "usage: mft-cyclone listen  --domain N [--seconds S] [--min-samples K] [--topic-prefix P] [--json]\n"
    "       mft-cyclone command --domain N --mode stand|step_in_place|walk --height Z [--speed V] [--wait S]\n"
    "                           [--topic-prefix P] [--json]\n"
    "\n"
    "A Cyclone DDS participant on the mft-wbc topics (docs/interop.md), built from idl/mft_msgs.idl.\n"
    "listen : reads SensorData, JointCommand and Reference for --seconds (default 3) or until each topic has\n"
    "         --min-samples samples; prints per topic: samples, first/last tick, tick decreases, non-finite\n"
    "         values, and value ranges (joint positions, torques, reference height). Exit 3 if a topic is silent.\n"
    "command: sends one OperatorCommand (reliable, transient-local, as mft-cmd does) and waits --wait seconds\n"
    "         (default 10) for the planner's CommandVerdict with its seq. Exit 0 applied, 1 rejected, 5 none.\n"
    "Topics are named as ROS 2 names them, --topic-prefix (default rt/mft/) + snake_case type name; types\n"
    "mft::msg::dds_::<Name>_. Only loopback is used (Cyclone's lo interface with multicast discovery).\n";

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int usage_error(const char *what) {
  fprintf(stderr, "mft-cyclone: %s (see --help)\n", what);
  return EXIT_USAGE;
}

static bool parse_double(const char *s, double lo, double hi, double *out) {
  char *end = NULL;
  const double v = strtod(s, &end);
  if (end == s || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) return false;
  *out = v;
  return true;
}

/* Loopback only, multicast discovery on lo (the stack's Fast DDS participants announce there). */
static dds_entity_t make_participant(int domain) {
  char config[512];
  snprintf(config, sizeof config,
           "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" multicast=\"true\"/>"
           "</Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>");
  dds_entity_t dom = dds_create_domain((dds_domainid_t)domain, config);
  if (dom < 0) return dom;
  return dds_create_participant((dds_domainid_t)domain, NULL, NULL);
}

typedef struct {
  const char *name;
  long samples;
  unsigned long long first_tick, last_tick;
  long tick_decreases;
  long nonfinite;
  double lo, hi; /* range of the topic's checked value */
} TopicStats;

static void stats_init(TopicStats *s, const char *name) {
  memset(s, 0, sizeof *s);
  s->name = name;
  s->lo = HUGE_VAL;
  s->hi = -HUGE_VAL;
}

static void stats_add(TopicStats *s, unsigned long long tick, const double *values, size_t n) {
  if (s->samples > 0 && tick < s->last_tick) s->tick_decreases++;
  if (s->samples == 0) s->first_tick = tick;
  s->last_tick = tick;
  s->samples++;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) {
      s->nonfinite++;
      continue;
    }
    if (values[i] < s->lo) s->lo = values[i];
    if (values[i] > s->hi) s->hi = values[i];
  }
}

static void stats_print(const TopicStats *s, bool json, const char *value_name, bool last) {
  if (json) {
    printf("  \"%s\": {\"samples\": %ld, \"first_tick\": %llu, \"last_tick\": %llu, \"tick_decreases\": %ld, "
           "\"nonfinite\": %ld, \"value\": \"%s\", \"min\": %.9g, \"max\": %.9g}%s\n",
           s->name, s->samples, s->first_tick, s->last_tick, s->tick_decreases, s->nonfinite, value_name,
           s->samples ? s->lo : 0.0, s->samples ? s->hi : 0.0, last ? "" : ",");
  } else {
    printf("%-13s %7ld samples, ticks %llu..%llu, %ld decreases, %ld non-finite, %s in [%.4g, %.4g]\n", s->name,
           s->samples, s->first_tick, s->last_tick, s->tick_decreases, s->nonfinite, value_name,
           s->samples ? s->lo : 0.0, s->samples ? s->hi : 0.0);
  }
}

static dds_entity_t make_reader(dds_entity_t participant, const dds_topic_descriptor_t *desc, const char *name,
                                bool reliable) {
  dds_entity_t topic = dds_create_topic(participant, desc, name, NULL, NULL);
  if (topic < 0) return topic;
  dds_qos_t *qos = dds_create_qos();
  dds_qset_reliability(qos, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 64);
  dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  return reader;
}

// Takes every sample waiting on `reader` and hands each valid one to `use`.
template <class Msg, class Use>
static void takeAll(dds_entity_t reader, Use use) {
  void* samples[16] = {};
  dds_sample_info_t infos[16];
  const int n = dds_take(reader, samples, infos, 16, 16);
  for (int i = 0; i < n; ++i)
    if (infos[i].valid_data) use(*static_cast<const Msg*>(samples[i]));
  if (n > 0) dds_return_loan(reader, samples, n);
}

static int cmd_listen(int domain, double seconds, long min_samples, const char *prefix, bool json) {
  dds_entity_t participant = make_participant(domain);
  if (participant < 0) {
    fprintf(stderr, "mft-cyclone: cannot create a participant on domain %d: %s\n", domain, dds_strretcode(-participant));
    return EXIT_USAGE;
  }
  char n_sensor[128], n_command[128], n_reference[128];
  snprintf(n_sensor, sizeof n_sensor, "%ssensor_data", prefix);
  snprintf(n_command, sizeof n_command, "%sjoint_command", prefix);
  snprintf(n_reference, sizeof n_reference, "%sreference", prefix);
  const dds_entity_t r_sensor = make_reader(participant, &mft_msg_dds__SensorData__desc, n_sensor, false);
  const dds_entity_t r_command = make_reader(participant, &mft_msg_dds__JointCommand__desc, n_command, false);
  const dds_entity_t r_reference = make_reader(participant, &mft_msg_dds__Reference__desc, n_reference, false);
  if (r_sensor < 0 || r_command < 0 || r_reference < 0) {
    fprintf(stderr, "mft-cyclone: cannot create the readers\n");
    dds_delete(participant);
    return EXIT_USAGE;
  }
  TopicStats sensor, command, reference;
  stats_init(&sensor, "SensorData");
  stats_init(&command, "JointCommand");
  stats_init(&reference, "Reference");
  dds_entity_t waitset = dds_create_waitset(participant);
  dds_entity_t conds[3];
  const dds_entity_t readers[3] = {r_sensor, r_command, r_reference};
  for (int i = 0; i < 3; ++i) {
    conds[i] = dds_create_readcondition(readers[i], DDS_ANY_STATE);
    dds_waitset_attach(waitset, conds[i], i);
  }
  const double t_end = now_s() + seconds;
  while (now_s() < t_end) {
    if (min_samples > 0 && sensor.samples >= min_samples && command.samples >= min_samples &&
        reference.samples >= min_samples)
      break;
    dds_waitset_wait(waitset, NULL, 0, DDS_MSECS(50));
    takeAll<mft_msg_dds__SensorData_>(r_sensor, [&](const auto& m) { stats_add(&sensor, m.tick, m.actuated_pos, 4); });
    takeAll<mft_msg_dds__JointCommand_>(r_command, [&](const auto& m) { stats_add(&command, m.tick, m.tau, 4); });
    takeAll<mft_msg_dds__Reference_>(r_reference, [&](const auto& m) { stats_add(&reference, m.tick, &m.base_z[0], 1); });
  }
  if (json) printf("{\n \"domain\": %d,\n \"topics\": {\n", domain);
  stats_print(&sensor, json, "actuated_pos [rad]", false);
  stats_print(&command, json, "tau [N m]", false);
  stats_print(&reference, json, "base_z [m]", true);
  if (json) printf(" }\n}\n");
  dds_delete(participant);
  if (sensor.samples == 0 || command.samples == 0 || reference.samples == 0) {
    fprintf(stderr, "mft-cyclone: no samples on %s within %.1f s\n",
            sensor.samples == 0 ? "SensorData" : command.samples == 0 ? "JointCommand" : "Reference", seconds);
    return EXIT_NO_DATA;
  }
  return EXIT_OK;
}

/* The QoS of the stack's event topics (operator commands, verdicts): reliable, transient local, the last `depth`. */
static dds_qos_t *reliable_transient_local(int32_t depth) {
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  return q;
}

static int cmd_command(int domain, int mode, double height, double speed, double wait_s, const char *prefix,
                       bool json) {
  dds_entity_t participant = make_participant(domain);
  if (participant < 0) {
    fprintf(stderr, "mft-cyclone: cannot create a participant on domain %d: %s\n", domain, dds_strretcode(-participant));
    return EXIT_USAGE;
  }
  char n_command[128], n_verdict[128];
  snprintf(n_command, sizeof n_command, "%soperator_command", prefix);
  snprintf(n_verdict, sizeof n_verdict, "%scommand_verdict", prefix);
  /* The verdict reader first, so that the answer cannot come before it exists (the planner's writer keeps its
   * history for late readers anyway: reliable, transient-local). */
  dds_entity_t t_verdict = dds_create_topic(participant, &mft_msg_dds__CommandVerdict__desc, n_verdict, NULL, NULL);
  dds_qos_t *rq = reliable_transient_local(16);
  const dds_entity_t r_verdict = dds_create_reader(participant, t_verdict, rq, NULL);
  dds_delete_qos(rq);
  dds_entity_t t_command = dds_create_topic(participant, &mft_msg_dds__OperatorCommand__desc, n_command, NULL, NULL);
  dds_qos_t *wq = reliable_transient_local(1);
  const dds_entity_t writer = dds_create_writer(participant, t_command, wq, NULL);
  dds_delete_qos(wq);
  if (r_verdict < 0 || writer < 0) {
    fprintf(stderr, "mft-cyclone: cannot create the command writer or the verdict reader\n");
    dds_delete(participant);
    return EXIT_USAGE;
  }
  const double t0 = now_s();
  /* Wait (bounded) until the planner's reader matched, so the command is not written into the void. */
  dds_publication_matched_status_t pm;
  while (now_s() - t0 < wait_s) {
    if (dds_get_publication_matched_status(writer, &pm) == 0 && pm.current_count > 0) break;
    dds_sleepfor(DDS_MSECS(10));
  }
  mft_msg_dds__OperatorCommand_ cmd;
  memset(&cmd, 0, sizeof cmd);
  cmd.seq = ((unsigned long long)getpid() << 20) ^ (unsigned long long)(now_s() * 1e6);
  cmd.z_cmd = height;
  cmd.v_cmd = speed;
  cmd.mode = (uint8_t)mode;
  if (dds_write(writer, &cmd) < 0) {
    fprintf(stderr, "mft-cyclone: writing the OperatorCommand failed\n");
    dds_delete(participant);
    return EXIT_USAGE;
  }
  int result = EXIT_NO_VERDICT;
  mft_msg_dds__CommandVerdict_ got;
  memset(&got, 0, sizeof got);
  void *samples[16];
  dds_sample_info_t infos[16];
  while (result == EXIT_NO_VERDICT && now_s() - t0 < wait_s) {
    memset(samples, 0, sizeof samples);
    const int n = dds_take(r_verdict, samples, infos, 16, 16);
    for (int i = 0; i < n; ++i) {
      const auto* v = static_cast<const mft_msg_dds__CommandVerdict_*>(samples[i]);
      if (!infos[i].valid_data || v->seq != cmd.seq || v->source != mft_msg_COMMAND_SOURCE_PLANNER) continue;
      if (v->verdict == mft_msg_VERDICT_SCHEDULED) continue; /* wait for APPLIED */
      got = *v;
      result = v->accepted ? EXIT_OK : EXIT_REJECTED;
    }
    if (n > 0) dds_return_loan(r_verdict, samples, n);
    if (result == EXIT_NO_VERDICT) dds_sleepfor(DDS_MSECS(5));
  }
  got.reason[sizeof got.reason - 1] = '\0';
  const char *what = result == EXIT_OK ? "applied" : result == EXIT_REJECTED ? "rejected" : "no verdict";
  if (json) {
    printf("{\"domain\": %d, \"seq\": %llu, \"matched\": %s, \"result\": \"%s\", \"tick\": %llu, \"after_s\": %.3f, "
           "\"reason\": \"",
           domain, (unsigned long long)cmd.seq, pm.current_count > 0 ? "true" : "false", what,
           (unsigned long long)got.tick, now_s() - t0);
    for (const char *c = got.reason; *c; ++c) {
      if (*c == '"' || *c == '\\') printf("\\%c", *c);
      else if ((unsigned char)*c < 0x20) printf("\\u%04x", (unsigned)*c);
      else putchar(*c);
    }
    printf("\"}\n");
  } else {
    printf("%s (seq %llu, tick %llu, %.3f s)%s%s\n", what, (unsigned long long)cmd.seq, (unsigned long long)got.tick, now_s() - t0, got.reason[0] ? ": " : "",
           got.reason);
  }
  dds_delete(participant);
  return result;
}

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
  if (listen) return cmd_listen((int)domain, seconds, (long)min_samples, prefix, json);
  if (mode < 0 || !std::isfinite(height)) return usage_error("command needs --mode and --height");
  return cmd_command((int)domain, mode, height, speed, wait_s, prefix, json);
}
