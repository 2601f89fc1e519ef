#include "model/config/tool_io.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ios>
#include <new>
#include <system_error>

#include "model/config/strict_yaml.hpp"

namespace mft::config {

std::string jsonEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size() + 8);
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      default:
        if (u < 0x20 || u == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(u));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out;
}

std::string jsonString(const std::string& text) { return "\"" + jsonEscape(text) + "\""; }

std::string jsonNumber(double value, int significant_digits) {
  if (!std::isfinite(value)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", significant_digits, value);
  return buf;
}

std::string oneLine(const std::string& text, std::size_t max_chars) {
  std::string out;
  for (const char c : text) {
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    out += static_cast<unsigned char>(c) < 0x20 ? ' ' : c;
  }
  return out;
}

int guardedMain(const char* program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "%s: I/O error: %s\n", program, oneLine(e.what()).c_str());
    return kExitIoOrInput;
  } catch (const std::ios_base::failure& e) {
    std::fprintf(stderr, "%s: I/O error: %s\n", program, oneLine(e.what()).c_str());
    return kExitIoOrInput;
  } catch (const std::system_error& e) {
    std::fprintf(stderr, "%s: system error: %s\n", program, oneLine(e.what()).c_str());
    return kExitIoOrInput;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "%s: %s\n", program, oneLine(e.what()).c_str());
    return kExitIoOrInput;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: out of memory\n", program);
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", program, oneLine(e.what()).c_str());
    return kExitInternal;
  }
}

}  // namespace mft::config
