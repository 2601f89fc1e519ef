#include "common/command_line.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace mft::config {

CommandLine::CommandLine(std::string program, std::string summary) : program_(std::move(program)), summary_(std::move(summary)) {
  flag("help", "print this help and exit");
}

void CommandLine::option(const std::string& name, const std::string& help, const std::string& default_value, bool required) {
  order_.push_back(name);
  specs_[name] = {help, default_value, true, required};
}

void CommandLine::flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = {help, "", false, false};
}

std::string CommandLine::usage() const {
  std::string u = "Usage: " + program_ + " [options]\n" + summary_ + "\n\nOptions:\n";
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    std::string left = "  --" + name + (s.takes_value ? " VALUE" : "");
    if (left.size() < 28) left.resize(28, ' ');
    u += left + " " + s.help;
    if (s.required) u += " (required)";
    else if (!s.default_value.empty()) u += " (default: " + s.default_value + ")";
    u += "\n";
  }
  return u;
}

void CommandLine::fail(const std::string& message) const {
  std::fprintf(stderr, "%s: %s\nTry '%s --help'.\n", program_.c_str(), message.c_str(), program_.c_str());
  std::exit(2);
}

std::string CommandLine::takeLeadingArgument(int* argc, char** argv) {
  if (*argc < 2 || std::string(argv[1]).rfind("--", 0) == 0) return "";
  std::string first = argv[1];
  for (int i = 1; i + 1 < *argc; ++i) argv[i] = argv[i + 1];
  --*argc;
  return first;
}

void CommandLine::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0) fail("unexpected argument '" + arg + "'");
    std::string name = arg.substr(2), value;
    const auto eq = name.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    auto it = specs_.find(name);
    if (it == specs_.end()) fail("unknown option --" + name);
    if (name == "help") {
      std::fputs(usage().c_str(), stdout);
      std::exit(0);
    }
    if (it->second.takes_value) {
      if (!inline_value) {
        if (i + 1 >= argc) fail("option --" + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
      all_values_[name].push_back(value);
    } else {
      if (inline_value) fail("option --" + name + " takes no value");
      values_[name] = "1";
    }
  }
  for (const auto& [name, spec] : specs_)
    if (spec.required && !values_.count(name)) fail("missing required option --" + name);
}

std::string CommandLine::get(const std::string& name) const {
  auto v = values_.find(name);
  if (v != values_.end()) return v->second;
  return specs_.at(name).default_value;
}

std::vector<std::string> CommandLine::getAll(const std::string& name) const {
  auto v = all_values_.find(name);
  return v != all_values_.end() ? v->second : std::vector<std::string>{};
}

bool CommandLine::isSet(const std::string& name) const { return values_.count(name) > 0; }

long CommandLine::getInt(const std::string& name, long lo, long hi) const {
  const std::string s = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno != 0) fail("--" + name + ": '" + s + "' is not an integer");
  if (v < lo || v > hi) fail("--" + name + ": " + s + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

double CommandLine::getDouble(const std::string& name, double lo, double hi) const {
  const std::string s = get(name);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0') fail("--" + name + ": '" + s + "' is not a number");
  if (!(v >= lo && v <= hi)) fail("--" + name + ": " + s + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

}  // namespace mft::config
