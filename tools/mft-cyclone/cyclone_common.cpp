// mft-cyclone's shared pieces (cyclone_common.hpp).
#include "cyclone_common.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>

double now_s() {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int usage_error(const char *what) {
  fprintf(stderr, "mft-cyclone: %s (see --help)\n", what);
  return EXIT_USAGE;
}

bool parse_double(const char *s, double lo, double hi, double *out) {
  char *end = NULL;
  const double v = strtod(s, &end);
  if (end == s || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) return false;
  *out = v;
  return true;
}

dds_entity_t make_participant(int domain) {
  char config[512];
  snprintf(config, sizeof config,
           "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" multicast=\"true\"/>"
           "</Interfaces><AllowMulticast>true</AllowMulticast></General></Domain></CycloneDDS>");
  dds_entity_t dom = dds_create_domain((dds_domainid_t)domain, config);
  if (dom < 0) return dom;
  return dds_create_participant((dds_domainid_t)domain, NULL, NULL);
}
