#pragma once
// Shared by the configuration loader tests: read a shipped file, break it with one regex replacement and
// expect the strict loader to refuse it with a ConfigError that names the file and the key.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "common/strict_yaml.hpp"

namespace mft::test {

inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `text` with the first match of `pattern` replaced (regex_replace format: $& is the match).
inline std::string replaceFirst(const std::string& text, const std::string& pattern, const std::string& replacement) {
  return std::regex_replace(text, std::regex(pattern), replacement, std::regex_constants::format_first_only);
}

// Replaces the first match of `pattern` in `text`, runs `parse(bad_text, origin)` and expects a ConfigError whose
// message contains both `origin` and `expect`.
template <class Parse>
void expectConfigError(const std::string& text, const std::string& pattern, const std::string& replacement,
                       const std::string& origin, const std::string& expect, Parse&& parse) {
  const std::string bad = replaceFirst(text, pattern, replacement);
  ASSERT_NE(bad, text) << "pattern did not match: " << pattern;
  try {
    parse(bad, origin);
    FAIL() << "expected a ConfigError containing '" << expect << "'";
  } catch (const config::ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(origin), std::string::npos) << msg;
    EXPECT_NE(msg.find(expect), std::string::npos) << msg;
  }
}

// The message of the ConfigError `apply()` throws, or "accepted" (a live change judged by a strict loader).
template <class Apply>
std::string refusalOf(Apply&& apply) {
  try {
    apply();
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace mft::test
