// mft-inject's command line: every topic of the registry (idl/topics.yaml) by name; `all` the ones the fault
// matrix corrupts.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/install_layout.hpp"
#include "services/runtime/process.hpp"
#include "tools/mft-inject/inject_session.hpp"

namespace mft::inject {

namespace {

std::string topicChoices() {
  std::string out;
  for (const auto& t : msg::kTopics) out += std::string(t.type) + ", ";
  return out + "or all";
}

std::vector<std::string> splitTopics(const std::string& text, const services::CommandLine& cli) {
  std::vector<std::string> out;
  if (text == "all") {
    for (const auto& t : msg::kTopics)
      if (t.faults) out.emplace_back(t.type);
    return out;
  }
  std::stringstream ss(text);
  std::string t;
  while (std::getline(ss, t, ',')) {
    if (t.empty()) continue;
    if (msg::topicIndex(t) < 0) cli.fail("unknown topic '" + t + "' (one of " + topicChoices() + ")");
    out.push_back(t);
  }
  return out;
}

void defineOptions(services::CommandLine& cli) {
  cli.option("domain", "DDS domain id (0..232)", "", true);
  cli.option("secure", "DDS Security directory (scripts/make-security.sh); default: no identity at all");
  cli.option("identity", "with --secure: the identity to use (sim, estimator, planner, wbc, record, cmd)", "cmd");
  cli.option("listen", "comma-separated topics to subscribe to and count, or 'all'");
  cli.option("publish", "the topic to publish on");
  cli.option("value", "published values: nan | inf | -inf | range (1e6 and enumerations out of range) | a number", "nan");
  cli.option("field", "comma-separated field names to set (default: every floating-point field)");
  cli.flag("follow", "re-publish every real sample of the --publish topic corrupted, at once");
  cli.option("tick-offset", "with --follow: add this to the copied tick (1: the corrupted sample is the newest)", "1");
  cli.option("rate", "without --follow: samples per second", "1000");
  cli.option("seconds", "how long to listen / publish (a listener alone stops early, and reports, on SIGTERM)", "3");
  cli.option("wait-match", "seconds to wait for a matching reader before publishing (0: do not wait)", "5");
  cli.option("wait-writers", "with --listen: seconds to wait until every listened topic has a matched writer before "
             "the --seconds window starts (0: do not wait)", "0");
  cli.option("profiles", "DDS QoS profile file",
             mft::config::dataFileFor("config/dds_profiles.xml", MFT_DDS_PROFILES));
  cli.flag("json", "print the report as JSON");
}

Corruption corruptionOf(const services::CommandLine& cli) {
  Corruption c;
  c.kind = cli.get("value");
  if (c.kind != "nan" && c.kind != "inf" && c.kind != "-inf" && c.kind != "range") {
    c.number = cli.getDouble("value", -1e300, 1e300);
    c.kind = "number";
  }
  if (cli.isSet("field")) {
    std::stringstream ss(cli.get("field"));
    std::string f;
    while (std::getline(ss, f, ','))
      if (!f.empty()) c.fields.insert(f);
  }
  return c;
}

}  // namespace

Options parseOptions(int argc, char** argv) {
  services::CommandLine cli(
      "mft-inject",
      "Test participant for the security tests and the fault matrix (docs/guide/security.md, docs/results/faults.md).\n"
      "  mft-inject --domain 190 --listen all --seconds 3 --json\n"
      "  mft-inject --domain 190 --secure DIR --identity cmd --publish JointCommand --value 20 --seconds 2\n"
      "  mft-inject --domain 190 --publish RobotState --follow --value nan --seconds 2 --json\n"
      "Exit status: 0, 2 on bad options, 4 when the participant or the writer was refused.");
  defineOptions(cli);
  cli.parse(argc, argv);
  Options o;
  o.domain = static_cast<int>(cli.getInt("domain", 0, services::kMaxDomainId));
  o.seconds = cli.getDouble("seconds", 0.0, 3600.0);
  o.wait_match = cli.getDouble("wait-match", 0.0, 600.0);
  o.wait_writers = cli.getDouble("wait-writers", 0.0, 600.0);
  o.rate = cli.getDouble("rate", 0.1, 100000.0);
  o.tick_offset = static_cast<std::int64_t>(cli.getInt("tick-offset", -1000000, 1000000000));
  if (cli.isSet("listen")) o.listen = splitTopics(cli.get("listen"), cli);
  if (cli.isSet("publish")) {
    const auto t = splitTopics(cli.get("publish"), cli);
    if (t.size() != 1) cli.fail("--publish takes exactly one topic");
    o.publish_topic = t.front();
  }
  if (o.listen.empty() && o.publish_topic.empty()) cli.fail("give --listen TOPICS and/or --publish TOPIC");
  o.value = cli.get("value");
  o.corruption = corruptionOf(cli);
  o.follow = cli.isSet("follow");
  if (o.follow && isEventTopic(o.publish_topic))
    cli.fail("--follow needs a 1 kHz topic (" + o.publish_topic + " is an event topic)");
  o.security = services::SecurityOptions{cli.get("secure"), cli.get("identity")};
  o.json = cli.isSet("json");
  o.profiles = cli.get("profiles");
  // A profile file that cannot be read is a usage error (exit 2), not a participant the stack refused (4).
  if (!std::ifstream(o.profiles).good() || std::filesystem::is_directory(o.profiles))
    cli.fail("--profiles: cannot read the DDS profile file " + o.profiles);
  return o;
}

}  // namespace mft::inject
