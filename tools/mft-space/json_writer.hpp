#pragma once
// Minimal JSON output for --json (objects, arrays, numbers, strings). Non-finite numbers become null.
#include <cmath>
#include <cstdio>
#include <string>

#include "model/config/tool_io.hpp"

namespace mft::tools {

inline std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

inline std::string jsonString(const std::string& s) { return config::jsonString(s); }

// Builds "{...}" from key/value pairs already rendered as JSON.
class JsonObject {
 public:
  JsonObject& raw(const std::string& key, const std::string& json) {
    body_ += (body_.empty() ? "" : ", ") + jsonString(key) + ": " + json;
    return *this;
  }
  JsonObject& num(const std::string& key, double v) { return raw(key, jsonNumber(v)); }
  JsonObject& str(const std::string& key, const std::string& v) { return raw(key, jsonString(v)); }
  JsonObject& boolean(const std::string& key, bool v) { return raw(key, v ? "true" : "false"); }
  std::string str() const { return "{" + body_ + "}"; }

 private:
  std::string body_;
};

}  // namespace mft::tools
