// HopTrace (services/runtime/hop_trace.hpp): off without MFT_HOP_TRACE; with it, one CSV row per traced tick,
// the first stamp of a mark kept, ticks beyond the capacity ignored.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "services/runtime/hop_trace.hpp"

namespace {

std::vector<std::string> readLines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<long long> numbers(const std::string& line) {
  std::vector<long long> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(std::stoll(cell));
  return out;
}

TEST(HopTrace, OffWithoutTheEnvironmentVariable) {
  unsetenv("MFT_HOP_TRACE");
  mft::services::HopTrace trace("unit-off", {"a"}, 10);
  EXPECT_FALSE(trace.enabled());
  trace.mark(0, 1);  // a no-op, not a crash
}

TEST(HopTrace, WritesTheFirstStampOfEachMarkPerTick) {
  const auto dir = std::filesystem::temp_directory_path() / ("mft-hop-trace-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  setenv("MFT_HOP_TRACE", dir.c_str(), 1);
  {
    mft::services::HopTrace trace("unit", {"in", "out"}, 10);
    ASSERT_TRUE(trace.enabled());
    trace.mark(0, 3);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    trace.mark(1, 3);
    trace.mark(0, 3);   // a re-sent tick: the first pass is kept
    trace.mark(0, 10);  // beyond the capacity: not traced
    trace.mark(1, 7);
  }
  unsetenv("MFT_HOP_TRACE");
  const auto lines = readLines(dir / "unit.hops.csv");
  std::filesystem::remove_all(dir);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "tick,in,out");
  const auto t3 = numbers(lines[1]);
  ASSERT_EQ(t3.size(), 3u);
  EXPECT_EQ(t3[0], 3);
  EXPECT_GT(t3[1], 0);
  // out was stamped 2 ms after in; had the second mark(0, 3) overwritten it, in would come after out.
  EXPECT_GE(t3[2] - t3[1], 1500000);
  const auto t7 = numbers(lines[2]);
  ASSERT_EQ(t7.size(), 3u);
  EXPECT_EQ(t7[0], 7);
  EXPECT_EQ(t7[1], 0);  // never stamped
  EXPECT_GT(t7[2], 0);
}

}  // namespace
