#pragma once
// Strict YAML reading for every mft-wbc configuration file: a missing key, an unknown key, a wrong type
// or an out-of-range value is a ConfigError whose message names the file and the full key path.
#include <array>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/enum_names.hpp"

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
  // "schema_version" must be `expected`, else "unsupported version v (expected e)".
  void expectSchemaVersion(int expected);
  // An integer in [lo, hi], else "must lie in [lo, hi]".
  int integerInRange(const std::string& key, int lo, int hi);
  // An integer >= 0, else "must be >= 0".
  int nonNegativeInteger(const std::string& key);
  // [lower, upper] with lower < upper (lower <= upper when allow_equal), else "expected [lower, upper] with ...",
  // returned as Bounds{lower, upper} (e.g. model::Interval).
  template <class Bounds = std::array<double, 2>>
  Bounds orderedPair(const std::string& key, bool allow_equal = false) {
    const auto v = orderedNumberPair(key, allow_equal);
    return Bounds{v[0], v[1]};
  }
  // One of the names in `table` (enum_names.hpp), else "expected a, b or c, got 'x'".
  template <class E, std::size_t N>
  E choice(const std::string& key, const EnumName<E> (&table)[N]) {
    const std::string name = text(key);
    E value{};
    if (!parseName(table, name, &value)) fail(key, "expected " + nameList(table) + ", got '" + name + "'");
    return value;
  }
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

  // Checks every number read from this mapping and its children against the range of configSchema()
  // (config_schema.hpp) for `stem` when finished: a number outside its range, or one the schema does not
  // list, is a ConfigError. Keys are named `prefix`.key (a node read apart from its file, e.g. a list entry).
  void useSchema(const std::string& stem, const std::string& prefix = "");

  // Throws ConfigError naming every key of this mapping (and of its children) that was never read, then
  // checks the numbers read against the schema (useSchema).
  void finish();

  // "file: key.path: message" for errors found by the caller after reading (e.g. cross-field checks).
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  const std::string& file() const;
  const std::string& path() const;

 private:
  struct Impl;
  enum class Shape { Scalar, List, Mapping };
  // The node at `key`, marked as read: "missing key" when absent, `expected` when not of `shape`.
  YAML::Node take(const std::string& key, Shape shape, const std::string& expected);
  // A scalar converted to T: `expected` when it is not a scalar, "<expected>, got 'text'" when it does not convert.
  template <class T>
  T scalar(const std::string& key, const std::string& expected);
  // Keeps the child mapping `name` (a key, or key[i] of a list) over `node`; finished with this node.
  StrictNode& addChild(const std::string& name, const YAML::Node& node);
  std::array<double, 2> orderedNumberPair(const std::string& key, bool allow_equal);
  void noteNumbers(const std::string& key, std::vector<double> values);
  void checkSchema() const;
  explicit StrictNode(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Every configuration type has a loader from a file and a parser of text, both running one reader
// (`read(StrictNode&)`, returning the configuration) over the strict root mapping: every file is at schema
// version 1, any key the reader left unread is an error, and the configuration's `source_file` names the file
// as messages do.
template <class Read>
auto readStrict(StrictNode& root, Read&& read) {
  root.expectSchemaVersion(1);
  auto result = read(root);
  result.source_file = root.file();
  root.finish();
  return result;
}
template <class Read>
auto loadStrictFile(const std::string& path, Read&& read) {
  StrictNode root = StrictNode::loadFile(path);
  return readStrict(root, read);
}
template <class Read>
auto parseStrictString(const std::string& text, const std::string& origin, Read&& read) {
  StrictNode root = StrictNode::loadString(text, origin);
  return readStrict(root, read);
}

// The plain YAML document of a file or a text, with the same ConfigError messages as StrictNode::loadFile
// and loadString ("cannot open the file", "not valid YAML: ..."), for readers that reshape the document.
YAML::Node readYamlFile(const std::string& path);
YAML::Node readYamlText(const std::string& text, const std::string& origin);

}  // namespace mft::config
