#pragma once
// One mft-inject run: its options, the participant with its publisher and listeners, the waits and the window,
// and the report (docs/guide/security.md, docs/results/faults.md).
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "services/runtime/dds_participant.hpp"
#include "tools/mft-inject/inject_topics.hpp"

namespace mft::inject {

struct Options {
  int domain = 0;
  double seconds = 3, wait_match = 5, wait_writers = 0, rate = 1000;
  std::int64_t tick_offset = 1;
  std::vector<std::string> listen;
  std::string publish_topic, value, profiles;
  Corruption corruption;
  bool follow = false, json = false;
  services::SecurityOptions security;
};
// The command line; exits 2 with a one-line reason on a bad option.
Options parseOptions(int argc, char** argv);

struct Session {
  std::string participant_status = "created", writer_status = "none", error;
  std::map<std::string, std::unique_ptr<Listener>> listeners;
  std::unique_ptr<Publisher> publisher;
  std::unique_ptr<services::DdsParticipant> participant;
  int exit_code = 0;
  double matched_after_s = -1.0, writers_matched_after_s = -1.0;

  // Joins the domain; a refused participant, writer or reader is recorded (status, error, exit 4), not thrown.
  void open(const Options& o);
  // Waits (bounded) for a reader of the publisher and for a writer on every listened topic.
  void awaitMatches(const Options& o);
  // Publishes or listens for --seconds (a pure listener stops early on SIGTERM/SIGINT).
  void runWindow(const Options& o);
  void report(const Options& o) const;
  // The readers feed the publisher: they go first.
  void close();

 private:
  void openPublisher(const Options& o, std::function<void(const void*)>* feed);
  void openListener(const Options& o, const std::string& topic, const std::function<void(const void*)>& feed);
};

}  // namespace mft::inject
