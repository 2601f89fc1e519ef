#pragma once
// Strict YAML reading for every mft-wbc configuration file: a missing key, an unknown key, a wrong type
// or an out-of-range value is a ConfigError whose message names the file and the full key path.
#include <array>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace mft::config {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A mapping node whose keys must all be consumed. Call finish() after reading all keys: any key that was
// never read is reported as unknown. Child mappings are finished automatically by their parent's finish().
class StrictNode {
 public:
  // Loads a file; throws ConfigError if it cannot be read or parsed or is not a mapping. A configuration file
  // that the active profiles change (profiles.hpp) is returned overlaid, named "<path> (profiles a, b)".
  static StrictNode loadFile(const std::string& path);
  // Parses YAML text (for tests and embedded defaults); `origin` names it in messages.
  static StrictNode loadString(const std::string& text, const std::string& origin);

  StrictNode(const StrictNode&) = delete;
  StrictNode& operator=(const StrictNode&) = delete;
  StrictNode(StrictNode&&) noexcept;
  StrictNode& operator=(StrictNode&&) noexcept;
  ~StrictNode();

  bool has(const std::string& key) const;
  StrictNode& child(const std::string& key);
  // Lists of mappings: listSize fails unless `key` is a list; item(key, i) is its i-th mapping, named
  // key[i] in messages and finished with this node.
  std::size_t listSize(const std::string& key);
  StrictNode& item(const std::string& key, std::size_t index);

  double number(const std::string& key);
  double positive(const std::string& key);     // > 0
  double nonNegative(const std::string& key);  // >= 0
  // lo <= v <= hi, else "must lie in [lo, hi] unit (got v)".
  double inRange(const std::string& key, double lo, double hi, const std::string& unit = "");
  int integer(const std::string& key);
  bool boolean(const std::string& key);
  std::string text(const std::string& key);
  std::vector<double> numbers(const std::string& key, std::size_t expected_size);  // 0 = any size
  std::vector<std::string> texts(const std::string& key);  // a list of strings
  // A list of numbers each in [lo, hi] (0 = any size).
  std::vector<double> numbersInRange(const std::string& key, std::size_t expected_size, double lo, double hi,
                                     const std::string& unit = "");
  template <std::size_t N>
  std::array<double, N> fixedInRange(const std::string& key, double lo, double hi, const std::string& unit = "") {
    const auto v = numbersInRange(key, N, lo, hi, unit);
    std::array<double, N> a{};
    for (std::size_t i = 0; i < N; ++i) a[i] = v[i];
    return a;
  }
  template <std::size_t N>
  std::array<double, N> fixed(const std::string& key) {
    const auto v = numbers(key, N);
    std::array<double, N> a{};
    for (std::size_t i = 0; i < N; ++i) a[i] = v[i];
    return a;
  }
  // Returns the list of keys of this mapping, marking none as used.
  std::vector<std::string> keys() const;

  // Throws ConfigError naming every key of this mapping (and of its children) that was never read.
  void finish();

  // "file: key.path: message" for errors found by the caller after reading (e.g. cross-field checks).
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  const std::string& file() const;
  const std::string& path() const;

 private:
  struct Impl;
  explicit StrictNode(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mft::config
