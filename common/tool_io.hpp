#pragma once
// What every command-line tool and service main shares for its output (no algorithm here): one JSON string
// escaping rule for every --json and summary, and the guard around a main that turns an exception escaping
// it into one line on stderr and a documented exit status instead of std::terminate (exit 134).
#include <functional>
#include <string>

#include "common/install_layout.hpp"  // the tools' data paths (configuration, scripts)
#include "common/json_writer.hpp"        // every --json and summary

namespace mft::config {

constexpr int kExitIoOrInput = 2;
constexpr int kExitInternal = 1;

// Runs `body` and returns its exit status. An exception that escapes it is reported as
// "<program>: <what>" on one line: I/O errors (std::filesystem::filesystem_error, std::ios_base::failure,
// std::system_error) and configuration errors exit 2, anything else (an internal error) exits 1.
int guardedMain(const char* program, const std::function<int()>& body);

// One line: newlines and other control characters of `text` replaced by spaces, at most `max_chars` long.
std::string oneLine(const std::string& text, std::size_t max_chars = 400);

}  // namespace mft::config
