#include "cli_args.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace mft::tools {

CliArgs::CliArgs(int argc, char** argv, int first, const std::set<std::string>& options,
                 const std::set<std::string>& flags) {
  for (int i = first; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "'");
    std::string name = a.substr(2), value;
    const auto eq = name.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) value = name.substr(eq + 1), name = name.substr(0, eq);
    if (flags.count(name)) {
      if (inline_value) throw UsageError("--" + name + " takes no value");
      flags_.insert(name);
    } else if (options.count(name)) {
      if (!inline_value) {
        if (i + 1 >= argc) throw UsageError("--" + name + " needs a value");
        value = argv[++i];
      }
      if (values_.count(name)) throw UsageError("--" + name + " given twice");
      values_[name] = value;
    } else {
      throw UsageError("unknown option --" + name + " for this command (see mft-space --help)");
    }
  }
}

std::string CliArgs::text(const std::string& name, const std::string& fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

std::string CliArgs::required(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw UsageError("missing required option --" + name);
  return it->second;
}

double CliArgs::parse(const std::string& name, const std::string& t) const {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end == t.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UsageError("--" + name + " expects a finite number, got '" + t + "'");
  return v;
}

double CliArgs::number(const std::string& name, double fallback) const {
  return has(name) ? parse(name, values_.at(name)) : fallback;
}

double CliArgs::positive(const std::string& name, double fallback) const {
  const double v = number(name, fallback);
  if (!(v > 0.0)) throw UsageError("--" + name + " must be > 0, got " + values_.at(name));
  return v;
}

int CliArgs::integer(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const std::string& t = values_.at(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (t.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
    throw UsageError("--" + name + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got '" + t + "'");
  return static_cast<int>(v);
}

}  // namespace mft::tools
