#pragma once
// The strict command-line parser of every service and tool: unknown options are errors, every program has
// --help, values are checked against their range; an error prints one line with a hint and exits 2.
#include <map>
#include <string>
#include <vector>

namespace mft::config {

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
  // `tool FILE [options]`: the parser takes options only, so a leading positional argument is taken off argv
  // first. Returns it ("" if argv[1] is missing or an option).
  static std::string takeLeadingArgument(int* argc, char** argv);

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

}  // namespace mft::config
