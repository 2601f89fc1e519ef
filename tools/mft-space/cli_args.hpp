#pragma once
// A small strict command-line parser: `--name value` options and `--flag` switches, each subcommand lists what
// it accepts; anything else is a UsageError (the tool exits with code 2 and the message).
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace mft::tools {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CliArgs {
 public:
  // Parses argv[first..argc); `options` take a value, `flags` do not.
  CliArgs(int argc, char** argv, int first, const std::set<std::string>& options, const std::set<std::string>& flags);

  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string text(const std::string& name, const std::string& fallback) const;
  std::string required(const std::string& name) const;
  double number(const std::string& name, double fallback) const;          // any finite number
  double positive(const std::string& name, double fallback) const;        // > 0
  int integer(const std::string& name, int fallback, int lo, int hi) const;

 private:
  double parse(const std::string& name, const std::string& text) const;
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
};

}  // namespace mft::tools
