// mft-cyclone command: one OperatorCommand written with Cyclone DDS, and the planner's CommandVerdict for it.
#include <cstdio>
#include <cstring>
#include <unistd.h>

#include "cyclone_common.hpp"

namespace {

/* The QoS of the stack's event topics (operator commands, verdicts): reliable, transient local, the last `depth`. */
dds_qos_t *reliable_transient_local(int32_t depth) {
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  return q;
}

struct Endpoints {
  dds_entity_t verdicts = -1, writer = -1;
};

/* The verdict reader first, so that the answer cannot come before it exists (the planner's writer keeps its
 * history for late readers anyway: reliable, transient-local). */
Endpoints open_endpoints(dds_entity_t participant, const char *prefix) {
  char n_command[128], n_verdict[128];
  snprintf(n_command, sizeof n_command, "%soperator_command", prefix);
  snprintf(n_verdict, sizeof n_verdict, "%scommand_verdict", prefix);
  Endpoints e;
  dds_entity_t t_verdict = dds_create_topic(participant, &mft_msg_dds__CommandVerdict__desc, n_verdict, NULL, NULL);
  dds_qos_t *rq = reliable_transient_local(16);
  e.verdicts = dds_create_reader(participant, t_verdict, rq, NULL);
  dds_delete_qos(rq);
  dds_entity_t t_command = dds_create_topic(participant, &mft_msg_dds__OperatorCommand__desc, n_command, NULL, NULL);
  dds_qos_t *wq = reliable_transient_local(1);
  e.writer = dds_create_writer(participant, t_command, wq, NULL);
  dds_delete_qos(wq);
  return e;
}

/* The planner's final verdict on `seq` (APPLIED or REJECTED; SCHEDULED is waited past), within `wait_s` of t0. */
int await_verdict(dds_entity_t reader, unsigned long long seq, double t0, double wait_s, mft_msg_dds__CommandVerdict_ *got) {
  int result = EXIT_NO_VERDICT;
  void *samples[16];
  dds_sample_info_t infos[16];
  while (result == EXIT_NO_VERDICT && now_s() - t0 < wait_s) {
    memset(samples, 0, sizeof samples);
    const int n = dds_take(reader, samples, infos, 16, 16);
    for (int i = 0; i < n; ++i) {
      const auto *v = static_cast<const mft_msg_dds__CommandVerdict_ *>(samples[i]);
      if (!infos[i].valid_data || v->seq != seq || v->source != mft_msg_COMMAND_SOURCE_PLANNER) continue;
      if (v->verdict == mft_msg_VERDICT_SCHEDULED) continue; /* wait for APPLIED */
      *got = *v;
      result = v->accepted ? EXIT_OK : EXIT_REJECTED;
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (result == EXIT_NO_VERDICT) dds_sleepfor(DDS_MSECS(5));
  }
  got->reason[sizeof got->reason - 1] = '\0';
  return result;
}

void print_verdict(int domain, int result, unsigned long long seq, bool matched, const mft_msg_dds__CommandVerdict_ &got,
                   double after_s, bool json) {
  const char *what = result == EXIT_OK ? "applied" : result == EXIT_REJECTED ? "rejected" : "no verdict";
  if (!json) {
    printf("%s (seq %llu, tick %llu, %.3f s)%s%s\n", what, seq, (unsigned long long)got.tick, after_s,
           got.reason[0] ? ": " : "", got.reason);
    return;
  }
  printf("{\"domain\": %d, \"seq\": %llu, \"matched\": %s, \"result\": \"%s\", \"tick\": %llu, \"after_s\": %.3f, "
         "\"reason\": \"",
         domain, seq, matched ? "true" : "false", what, (unsigned long long)got.tick, after_s);
  for (const char *c = got.reason; *c; ++c) {
    if (*c == '"' || *c == '\\') printf("\\%c", *c);
    else if ((unsigned char)*c < 0x20) printf("\\u%04x", (unsigned)*c);
    else putchar(*c);
  }
  printf("\"}\n");
}

}  // namespace

int cmd_command(int domain, int mode, double height, double speed, double wait_s, const char *prefix, bool json) {
  dds_entity_t participant = make_participant(domain);
  if (participant < 0) {
    fprintf(stderr, "mft-cyclone: cannot create a participant on domain %d: %s\n", domain, dds_strretcode(-participant));
    return EXIT_USAGE;
  }
  const Endpoints e = open_endpoints(participant, prefix);
  if (e.verdicts < 0 || e.writer < 0) {
    fprintf(stderr, "mft-cyclone: cannot create the command writer or the verdict reader\n");
    dds_delete(participant);
    return EXIT_USAGE;
  }
  const double t0 = now_s();
  /* Wait (bounded) until the planner's reader matched, so the command is not written into the void. */
  dds_publication_matched_status_t pm;
  memset(&pm, 0, sizeof pm);
  while (now_s() - t0 < wait_s) {
    if (dds_get_publication_matched_status(e.writer, &pm) == 0 && pm.current_count > 0) break;
    dds_sleepfor(DDS_MSECS(10));
  }
  mft_msg_dds__OperatorCommand_ cmd;
  memset(&cmd, 0, sizeof cmd);
  cmd.seq = ((unsigned long long)getpid() << 20) ^ (unsigned long long)(now_s() * 1e6);
  cmd.z_cmd = height;
  cmd.v_cmd = speed;
  cmd.mode = (uint8_t)mode;
  if (dds_write(e.writer, &cmd) < 0) {
    fprintf(stderr, "mft-cyclone: writing the OperatorCommand failed\n");
    dds_delete(participant);
    return EXIT_USAGE;
  }
  mft_msg_dds__CommandVerdict_ got;
  memset(&got, 0, sizeof got);
  const int result = await_verdict(e.verdicts, cmd.seq, t0, wait_s, &got);
  print_verdict(domain, result, (unsigned long long)cmd.seq, pm.current_count > 0, got, now_s() - t0, json);
  dds_delete(participant);
  return result;
}
