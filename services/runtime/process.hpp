#pragma once
// Process-level plumbing shared by the service mains: shutdown on SIGINT/SIGTERM, optional real-time
// scheduling with a graceful fallback, the readiness line the supervisor waits for, and a small strict
// command-line parser (unknown options are errors, every service has --help).
#include <atomic>
#include <map>
#include <string>
#include <vector>

namespace mft::services {

// Installs SIGINT/SIGTERM handlers that only set a flag (async-signal-safe).
void installShutdownHandlers();
bool shutdownRequested();
void requestShutdown();

// Tries SCHED_FIFO at `priority` and mlockall; on failure prints a warning to stderr and carries on.
// Returns true when both took effect. Call before creating the DDS participant so its threads inherit it.
bool tryRealtimeScheduling(int priority);

// The line the supervisor waits for on stdout: "READY <service>".
void announceReady(const std::string& service);

class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);
  // Declares an option taking a value (`--name VALUE`), with a default ("" = required unless optional).
  void option(const std::string& name, const std::string& help, const std::string& default_value = "",
              bool required = false);
  void flag(const std::string& name, const std::string& help);
  // Parses argv. On --help prints usage and exits 0; on an error prints it with a hint and exits 2.
  void parse(int argc, char** argv);
  std::string get(const std::string& name) const;  // the last value of an option given more than once
  std::vector<std::string> getAll(const std::string& name) const;  // every value, in command-line order
  bool isSet(const std::string& name) const;
  long getInt(const std::string& name, long lo, long hi) const;  // exits 2 with a message when out of range
  double getDouble(const std::string& name, double lo, double hi) const;
  std::string usage() const;
  [[noreturn]] void fail(const std::string& message) const;

 private:
  struct Spec {
    std::string help, default_value;
    bool takes_value = true, required = false;
  };
  std::string program_, summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::map<std::string, std::string> values_;
  std::map<std::string, std::vector<std::string>> all_values_;
};

}  // namespace mft::services
