// The services' strict command line: values, defaults, ranges, and clear exits on bad input.
#include <gtest/gtest.h>

#include <vector>

#include "services/runtime/process.hpp"

using mft::services::CommandLine;

namespace {
CommandLine makeCli() {
  CommandLine cli("mft-test", "A test service.");
  cli.option("domain", "DDS domain id", "", true);
  cli.option("mode", "lockstep or realtime", "lockstep");
  cli.flag("rt", "try SCHED_FIFO");
  return cli;
}
void parse(CommandLine& cli, std::vector<const char*> args) {
  args.insert(args.begin(), "mft-test");
  cli.parse(static_cast<int>(args.size()), const_cast<char**>(args.data()));
}
}  // namespace

TEST(CommandLine, ValuesDefaultsAndFlags) {
  auto cli = makeCli();
  parse(cli, {"--domain", "17", "--rt"});
  EXPECT_EQ(cli.getInt("domain", 0, 232), 17);
  EXPECT_EQ(cli.get("mode"), "lockstep");
  EXPECT_TRUE(cli.isSet("rt"));
  auto cli2 = makeCli();
  parse(cli2, {"--domain=3", "--mode=realtime"});
  EXPECT_EQ(cli2.get("mode"), "realtime");
  EXPECT_FALSE(cli2.isSet("rt"));
}

TEST(CommandLine, UsageListsEveryOption) {
  const std::string u = makeCli().usage();
  for (const char* s : {"--domain VALUE", "(required)", "--mode VALUE", "(default: lockstep)", "--rt", "--help"})
    EXPECT_NE(u.find(s), std::string::npos) << s;
}

using CommandLineDeathTest = ::testing::Test;
TEST(CommandLineDeathTest, BadInputExitsWithCode2AndAMessage) {
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {"--domain", "1", "--bogus"}); }, ::testing::ExitedWithCode(2), "unknown option --bogus");
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {}); }, ::testing::ExitedWithCode(2), "missing required option --domain");
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {"--domain"}); }, ::testing::ExitedWithCode(2), "needs a value");
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {"--domain", "x7"}); c.getInt("domain", 0, 232); }, ::testing::ExitedWithCode(2), "not an integer");
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {"--domain", "300"}); c.getInt("domain", 0, 232); }, ::testing::ExitedWithCode(2), "outside \\[0, 232\\]");
  EXPECT_EXIT({ auto c = makeCli(); parse(c, {"--help"}); }, ::testing::ExitedWithCode(0), "");
}
