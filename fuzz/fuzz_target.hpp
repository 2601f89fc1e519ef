#pragma once
// One fuzz target: runOne() feeds one input to one parser of outside bytes and says how the parser took it. A
// target file is linked twice: with libfuzzer_entry.cpp (clang's libFuzzer and sanitizers, scripts/fuzz.sh) and
// with replay_main.cpp in every build, which runs each file of fuzz/corpus/<target>/ once (ctest -L fuzz). The
// parser's documented refusal (its own error type, with a message naming the input) is an outcome; anything else
// that escapes runOne (another exception, a crash, a hang, undefined behaviour under the sanitizers) is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace mft::fuzz {

struct Outcome {
  bool accepted = false;
  std::string message;  // accepted: what was read; refused: the parser's error (never empty)
};

Outcome runOne(const std::uint8_t* data, std::size_t size);

inline Outcome acceptedAs(std::string what) { return {true, std::move(what)}; }
// A refusal must say what is wrong and name what it refers to (`origin`): an empty or anonymous message is a
// finding too.
inline Outcome refusedWith(const std::string& message, const std::string& origin) {
  if (message.empty() || message.find(origin) == std::string::npos)
    throw std::logic_error("a refusal that does not name '" + origin + "': '" + message + "'");
  return {false, message};
}
inline std::string bytesText(const std::uint8_t* data, std::size_t size) {
  return size == 0 ? std::string() : std::string(reinterpret_cast<const char*>(data), size);
}

}  // namespace mft::fuzz
