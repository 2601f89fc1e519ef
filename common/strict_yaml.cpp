#include "common/strict_yaml.hpp"

#include "common/config_schema.hpp"
#include "common/json_writer.hpp"
#include "common/profiles.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <type_traits>

namespace mft::config {

struct StrictNode::Impl {
  YAML::Node node;
  std::string file;
  std::string path;  // dotted key path of this mapping, "" at the root
  std::set<std::string> used;
  std::map<std::string, std::unique_ptr<StrictNode>> children;
  std::string schema;         // configSchema() stem, "" = not checked
  std::string schema_prefix;  // path of this node in the schema's key names
  std::vector<std::pair<std::string, std::vector<double>>> numbers_read;  // key -> values, checked in finish()
};

namespace {
std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
}  // namespace

StrictNode::StrictNode(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
StrictNode::StrictNode(StrictNode&&) noexcept = default;
StrictNode& StrictNode::operator=(StrictNode&&) noexcept = default;
StrictNode::~StrictNode() = default;

YAML::Node readYamlText(const std::string& text, const std::string& origin) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
}

YAML::Node readYamlFile(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ConfigError(path + ": cannot open the file");
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ": not valid YAML: " + e.what());
  }
}

StrictNode StrictNode::loadString(const std::string& text, const std::string& origin) {
  auto impl = std::make_unique<Impl>();
  impl->file = origin;
  impl->node = readYamlText(text, origin);
  if (!impl->node.IsMap()) throw ConfigError(origin + ": expected a mapping of keys at the top level");
  return StrictNode(std::move(impl));
}

StrictNode StrictNode::loadFile(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  impl->file = path;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ConfigError(path + ": is a directory, not a YAML file");
  impl->node = readYamlFile(path);
  if (!impl->node.IsMap()) throw ConfigError(path + ": expected a mapping of keys at the top level");
  // The active profiles (profiles.hpp) change the configuration files they name, for every loader alike.
  const ProfileSet& profiles = activeProfiles();
  const std::string stem = profileStemOf(path);
  if (!stem.empty() && profiles.touches(stem)) {
    applyProfiles(profiles, stem, &impl->node, path);
    impl->file = path + " (profiles " + profiles.describe() + ")";
  }
  return StrictNode(std::move(impl));
}

void StrictNode::fail(const std::string& key, const std::string& message) const {
  throw ConfigError(impl_->file + ": " + join(impl_->path, key) + ": " + message);
}
const std::string& StrictNode::file() const { return impl_->file; }
const std::string& StrictNode::path() const { return impl_->path; }

bool StrictNode::has(const std::string& key) const { return static_cast<bool>(impl_->node[key]); }

std::vector<std::string> StrictNode::keys() const {
  std::vector<std::string> k;
  for (const auto& kv : impl_->node) k.push_back(kv.first.as<std::string>());
  return k;
}

YAML::Node StrictNode::take(const std::string& key, Shape shape, const std::string& expected) {
  const YAML::Node n = impl_->node[key];
  if (!n) fail(key, "missing key");
  const bool fits = shape == Shape::Scalar ? n.IsScalar() : shape == Shape::List ? n.IsSequence() : n.IsMap();
  if (!fits) fail(key, expected);
  impl_->used.insert(key);
  return n;
}

namespace {
// A number must be a plain scalar: `!!str 5` or "5" is text, which yaml-cpp would otherwise convert.
bool plainOrNumericTag(const YAML::Node& n) {
  const std::string& tag = n.Tag();
  return tag == "?" || tag == "tag:yaml.org,2002:int" || tag == "tag:yaml.org,2002:float";
}
}  // namespace

template <class T>
T StrictNode::scalar(const std::string& key, const std::string& expected) {
  const YAML::Node n = take(key, Shape::Scalar, expected);
  if (!std::is_same<T, bool>::value && !plainOrNumericTag(n))
    fail(key, expected + ", got the text '" + n.Scalar() + "'");
  try {
    return n.as<T>();
  } catch (const YAML::Exception&) {
    fail(key, expected + ", got '" + n.Scalar() + "'");
  }
}

StrictNode& StrictNode::addChild(const std::string& name, const YAML::Node& node) {
  auto impl = std::make_unique<Impl>();
  impl->node = node;
  impl->file = impl_->file;
  impl->path = join(impl_->path, name);
  impl->schema = impl_->schema;
  impl->schema_prefix = impl_->schema_prefix;
  auto& slot = impl_->children[name];
  slot.reset(new StrictNode(std::move(impl)));
  return *slot;
}

StrictNode& StrictNode::child(const std::string& key) {
  auto it = impl_->children.find(key);
  if (it != impl_->children.end()) return *it->second;
  return addChild(key, take(key, Shape::Mapping, "expected a mapping"));
}

std::size_t StrictNode::listSize(const std::string& key) { return take(key, Shape::List, "expected a list").size(); }

StrictNode& StrictNode::item(const std::string& key, std::size_t index) {
  const std::string name = key + "[" + std::to_string(index) + "]";
  auto it = impl_->children.find(name);
  if (it != impl_->children.end()) return *it->second;
  if (index >= listSize(key)) fail(name, "no such list element");
  const YAML::Node n = impl_->node[key][index];
  if (!n.IsMap()) fail(name, "expected a mapping");
  return addChild(name, n);
}

double StrictNode::number(const std::string& key) {
  const double v = scalar<double>(key, "expected a number");
  if (!std::isfinite(v)) fail(key, "must be finite");
  noteNumbers(key, {v});
  return v;
}

double StrictNode::positive(const std::string& key) {
  const double v = number(key);
  if (!(v > 0.0)) fail(key, "must be > 0 (got " + std::to_string(v) + ")");
  return v;
}

double StrictNode::nonNegative(const std::string& key) {
  const double v = number(key);
  if (!(v >= 0.0)) fail(key, "must be >= 0 (got " + std::to_string(v) + ")");
  return v;
}

namespace {
std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

double StrictNode::inRange(const std::string& key, double lo, double hi, const std::string& unit) {
  const double v = number(key);
  if (!(v >= lo && v <= hi))
    fail(key, "must lie in [" + shortNumber(lo) + ", " + shortNumber(hi) + "]" + (unit.empty() ? "" : " " + unit) +
                  " (got " + shortNumber(v) + ")");
  return v;
}

std::vector<double> StrictNode::numbersInRange(const std::string& key, std::size_t expected_size, double lo, double hi,
                                               const std::string& unit) {
  const auto v = numbers(key, expected_size);
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!(v[i] >= lo && v[i] <= hi))
      fail(key, "element " + std::to_string(i) + " must lie in [" + shortNumber(lo) + ", " + shortNumber(hi) + "]" +
                    (unit.empty() ? "" : " " + unit) + " (got " + shortNumber(v[i]) + ")");
  return v;
}

int StrictNode::integer(const std::string& key) {
  const int v = scalar<int>(key, "expected an integer");
  if (!(impl_->path.empty() && key == "schema_version")) noteNumbers(key, {static_cast<double>(v)});
  return v;
}

bool StrictNode::boolean(const std::string& key) { return scalar<bool>(key, "expected true or false"); }

void StrictNode::expectSchemaVersion(int expected) {
  const int version = integer("schema_version");
  if (version != expected)
    fail("schema_version",
         "unsupported version " + std::to_string(version) + " (expected " + std::to_string(expected) + ")");
}

int StrictNode::integerInRange(const std::string& key, int lo, int hi) {
  const int v = integer(key);
  if (v < lo || v > hi) fail(key, "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

int StrictNode::nonNegativeInteger(const std::string& key) {
  const int v = integer(key);
  if (v < 0) fail(key, "must be >= 0");
  return v;
}

std::array<double, 2> StrictNode::orderedNumberPair(const std::string& key, bool allow_equal) {
  const auto v = fixed<2>(key);
  if (allow_equal ? !(v[0] <= v[1]) : !(v[0] < v[1]))
    fail(key, allow_equal ? "expected [lower, upper] with lower <= upper" : "expected [lower, upper] with lower < upper");
  return v;
}

std::string StrictNode::text(const std::string& key) {
  const std::string value = take(key, Shape::Scalar, "expected a string").Scalar();
  // Text goes into summaries and JSON reports, which are UTF-8: a Latin-1 byte is refused here, with its place.
  for (std::size_t i = 0; i < value.size(); i += utf8Length(value, i))
    if (utf8Length(value, i) == 0)
      fail(key, "not UTF-8 text (byte " + std::to_string(i) + " is 0x" + "0123456789abcdef"[(value[i] >> 4) & 0xf] +
                    "0123456789abcdef"[value[i] & 0xf] + "); save the file as UTF-8");
  return value;
}

std::vector<double> StrictNode::numbers(const std::string& key, std::size_t expected_size) {
  const YAML::Node n = take(key, Shape::List, "expected a list of numbers");
  if (expected_size != 0 && n.size() != expected_size)
    fail(key, "expected " + std::to_string(expected_size) + " numbers, got " + std::to_string(n.size()));
  std::vector<double> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    if (!n[i].IsScalar() || !plainOrNumericTag(n[i])) fail(key, "element " + std::to_string(i) + " is not a number");
    try {
      v = n[i].as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "element " + std::to_string(i) + " is not a number");
    }
    if (!std::isfinite(v)) fail(key, "element " + std::to_string(i) + " must be finite");
    out.push_back(v);
  }
  noteNumbers(key, out);
  return out;
}

std::vector<std::string> StrictNode::texts(const std::string& key) {
  const YAML::Node n = take(key, Shape::List, "expected a list of strings");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(key, "element " + std::to_string(i) + " is not a string");
    if (!isUtf8(n[i].Scalar())) fail(key, "element " + std::to_string(i) + " is not UTF-8 text");
    out.push_back(n[i].Scalar());
  }
  return out;
}

void StrictNode::finish() {
  std::vector<std::string> unknown;
  for (const auto& kv : impl_->node) {
    const auto k = kv.first.as<std::string>();
    if (!impl_->used.count(k)) unknown.push_back(k);
  }
  if (!unknown.empty()) {
    std::string list;
    for (const auto& k : unknown) list += (list.empty() ? "" : ", ") + join(impl_->path, k);
    throw ConfigError(impl_->file + ": unknown key" + (unknown.size() > 1 ? "s " : " ") + list);
  }
  for (auto& c : impl_->children) c.second->finish();
  checkSchema();
}

void StrictNode::useSchema(const std::string& stem, const std::string& prefix) {
  impl_->schema = stem;
  impl_->schema_prefix = prefix;
}

void StrictNode::noteNumbers(const std::string& key, std::vector<double> values) {
  if (!impl_->schema.empty()) impl_->numbers_read.emplace_back(key, std::move(values));
}

void StrictNode::checkSchema() const {
  for (const auto& [key, values] : impl_->numbers_read) {
    const std::string name = join(impl_->schema_prefix, join(impl_->path, key));
    const KeyRange* range = findKeyRange(impl_->schema, name);
    if (!range) fail(key, "no range in the configuration schema for " + impl_->schema + " key " + name);
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::string why = rangeViolation(*range, values[i]);
      if (!why.empty()) fail(key, (values.size() > 1 ? "element " + std::to_string(i) + " " : "") + why);
    }
  }
}

}  // namespace mft::config
