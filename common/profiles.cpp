#include "common/profiles.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "common/strict_yaml.hpp"

namespace mft::config {

struct ProfileSet::Impl {
  struct Entry {
    std::string name, file;
    YAML::Node overlay;  // mapping: stem -> mapping of replaced keys
  };
  std::vector<Entry> entries;
  std::vector<std::string> names;
};

namespace {

const char* kindOf(const YAML::Node& n) {
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list";
  return "a value";
}

// Replaces, key by key, the leaves of `base` with those of `overlay`; both are mappings.
void overlayInto(YAML::Node base, const YAML::Node& overlay, const std::string& profile_file, const std::string& path,
                 const std::string& origin) {
  for (const auto& kv : overlay) {
    const std::string key = kv.first.as<std::string>();
    const std::string key_path = path + "." + key;
    const YAML::Node old = static_cast<const YAML::Node&>(base)[key];  // const: never inserts
    if (!old)
      throw ConfigError(profile_file + ": " + key_path + ": no such key in " + origin +
                        " (a profile only replaces existing keys)");
    const YAML::Node& value = kv.second;
    if (value.IsMap() != old.IsMap())
      throw ConfigError(profile_file + ": " + key_path + ": is " + kindOf(value) + " but " + origin + " has " +
                        kindOf(old) + " there");
    if (value.IsMap()) {
      overlayInto(base[key], value, profile_file, key_path, origin);
    } else {
      base[key] = YAML::Clone(value);
    }
  }
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ProfileSet& active() {
  static ProfileSet set;
  return set;
}

}  // namespace

const std::vector<std::string>& profileStems() {
  static const std::vector<std::string> stems = {"robot", "sim", "estimator", "planner", "wbc"};
  return stems;
}

ProfileSet::ProfileSet() : impl_(std::make_unique<Impl>()) {}
ProfileSet::ProfileSet(const ProfileSet& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
ProfileSet& ProfileSet::operator=(const ProfileSet& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
ProfileSet::ProfileSet(ProfileSet&&) noexcept = default;
ProfileSet& ProfileSet::operator=(ProfileSet&&) noexcept = default;
ProfileSet::~ProfileSet() = default;

ProfileSet ProfileSet::load(const std::string& config_dir, const std::vector<std::string>& names) {
  ProfileSet set;
  for (const auto& name : names) {
    if (name.empty() || name.find('/') != std::string::npos || name.find('.') == 0)
      throw ConfigError("profile '" + name + "': expected a name from " + config_dir + "/profiles/ (no path)");
    if (std::find(set.impl_->names.begin(), set.impl_->names.end(), name) != set.impl_->names.end())
      throw ConfigError("profile '" + name + "' is given twice");
    const std::string file = config_dir + "/profiles/" + name + ".yaml";
    YAML::Node node;
    try {
      node = YAML::LoadFile(file);
    } catch (const YAML::BadFile&) {
      throw ConfigError("profile '" + name + "': cannot open " + file);
    } catch (const YAML::Exception& e) {
      throw ConfigError(file + ": not valid YAML: " + e.what());
    }
    if (!node.IsMap() || node.size() == 0)
      throw ConfigError(file + ": expected a mapping of configuration file stems (robot, sim, estimator, planner, wbc)");
    for (const auto& kv : node) {
      const std::string stem = kv.first.as<std::string>();
      const auto& stems = profileStems();
      if (std::find(stems.begin(), stems.end(), stem) == stems.end())
        throw ConfigError(file + ": " + stem + ": not a configuration file a profile may change (robot, sim, "
                          "estimator, planner, wbc)");
      if (!kv.second.IsMap() || kv.second.size() == 0)
        throw ConfigError(file + ": " + stem + ": expected a mapping of the keys of " + stem + ".yaml to replace");
    }
    set.impl_->entries.push_back({name, file, node});
    set.impl_->names.push_back(name);
  }
  return set;
}

bool ProfileSet::empty() const { return impl_->entries.empty(); }
const std::vector<std::string>& ProfileSet::names() const { return impl_->names; }

std::string ProfileSet::describe() const {
  std::string out;
  for (const auto& n : impl_->names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

bool ProfileSet::touches(const std::string& stem) const {
  for (const auto& e : impl_->entries)
    if (e.overlay[stem]) return true;
  return false;
}

void applyProfiles(const ProfileSet& profiles, const std::string& stem, YAML::Node* base, const std::string& origin) {
  for (const auto& e : profiles.impl().entries) {
    const YAML::Node section = e.overlay[stem];
    if (section) overlayInto(*base, section, e.file, stem, origin);
  }
}

std::string ProfileSet::applyToText(const std::string& stem, const std::string& base_text,
                                    const std::string& origin) const {
  if (!touches(stem)) return base_text;
  YAML::Node base;
  try {
    base = YAML::Load(base_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
  if (!base.IsMap()) throw ConfigError(origin + ": expected a mapping of keys at the top level");
  applyProfiles(*this, stem, &base, origin);
  YAML::Emitter out;
  out << base;
  return "# " + origin + " with the profiles " + describe() + " applied (config/profiles/)\n" + out.c_str() + "\n";
}

void ProfileSet::check(const std::string& config_dir) const {
  for (const auto& stem : profileStems()) {
    if (!touches(stem)) continue;
    const std::string file = config_dir + "/" + stem + ".yaml";
    applyToText(stem, readText(file), file);
  }
}

void setActiveProfiles(ProfileSet profiles) { active() = std::move(profiles); }
const ProfileSet& activeProfiles() { return active(); }

ScopedProfiles::ScopedProfiles(ProfileSet profiles) : previous_(active()) { active() = std::move(profiles); }
ScopedProfiles::~ScopedProfiles() { active() = std::move(previous_); }

std::string profileStemOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string suffix = ".yaml";
  if (base.size() <= suffix.size() || base.compare(base.size() - suffix.size(), suffix.size(), suffix) != 0) return "";
  const std::string stem = base.substr(0, base.size() - suffix.size());
  const auto& stems = profileStems();
  return std::find(stems.begin(), stems.end(), stem) == stems.end() ? "" : stem;
}

std::vector<std::string> splitProfileNames(const std::vector<std::string>& values) {
  std::vector<std::string> names;
  for (const auto& v : values) {
    std::stringstream ss(v);
    std::string item;
    while (std::getline(ss, item, ',')) {
      item.erase(0, item.find_first_not_of(" \t"));
      item.erase(item.find_last_not_of(" \t") + 1);
      if (!item.empty()) names.push_back(item);
    }
  }
  return names;
}

}  // namespace mft::config
