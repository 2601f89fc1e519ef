#include "common/tool_io.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ios>
#include <new>
#include <system_error>

#include "common/strict_yaml.hpp"

namespace mft::config {

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
