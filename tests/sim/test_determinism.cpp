// Same inputs -> bit-identical trajectories, in one process and across processes.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <string>

#include "sim_test_support.hpp"

using namespace mft::sim;

namespace {
std::string hex(std::uint64_t h) {
  char b[17];
  std::snprintf(b, sizeof b, "%016" PRIx64, h);
  return b;
}
std::string runProbe() {
  const std::string cmd = std::string(MFT_BIN_DIR) + "/sim_hash_probe";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return "popen failed";
  char buf[64] = {0};
  const char* ok = std::fgets(buf, sizeof buf, p);
  const int rc = pclose(p);
  if (!ok || rc != 0) return "probe failed";
  std::string s(buf);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}
}  // namespace

TEST(SimDeterminism, BitIdenticalInProcessAndAcrossProcesses) {
  Simulator a(test::robot(), test::options(), test::terrainFile("course.yaml"));
  const std::uint64_t h1 = test::runHashEpisode(a);
  const std::uint64_t h2 = test::runHashEpisode(a);  // same simulator, after reset
  Simulator b(test::robot(), test::options(), test::terrainFile("course.yaml"));
  const std::uint64_t h3 = test::runHashEpisode(b);  // a second simulator in the same process
  EXPECT_EQ(h1, h2);
  EXPECT_EQ(h1, h3);
  EXPECT_GT(a.stats().body_contact_steps, 0u) << "the episode should end in a fall with body impacts";
  const std::string p1 = runProbe(), p2 = runProbe();
  std::cout << "in-process " << hex(h1) << ", process 1 " << p1 << ", process 2 " << p2 << "\n";
  EXPECT_EQ(p1, hex(h1));
  EXPECT_EQ(p2, hex(h1));
}
