#pragma once
// mft-cyclone's shared pieces: exit codes, the clock, option parsing, the loopback participant, and the topics
// of the registry over Cyclone's C types (generated: mft_cyclone_topics.hpp, idl/topics.yaml).
#include <dds/dds.h>

extern "C" {
#include "mft_msgs.h"
}
#include "mft_cyclone_topics.hpp"

enum { EXIT_OK = 0, EXIT_REJECTED = 1, EXIT_USAGE = 2, EXIT_NO_DATA = 3, EXIT_NO_VERDICT = 5 };

double now_s();
int usage_error(const char *what);
bool parse_double(const char *s, double lo, double hi, double *out);
// Loopback only, multicast discovery on lo (the stack's Fast DDS participants announce there).
dds_entity_t make_participant(int domain);

// listen: reads `topics` (comma-separated registry names) for `seconds` or until each has `min_samples`.
int cmd_listen(int domain, double seconds, long min_samples, const char *prefix, const char *topics, bool json);
// command: one OperatorCommand, then the planner's CommandVerdict for it.
int cmd_command(int domain, int mode, double height, double speed, double wait_s, const char *prefix, bool json);
