#pragma once
// Named configuration profiles (docs/guide/profiles.md): config/profiles/<name>.yaml overlays whose top-level keys
// are the stems of the configuration files (robot, sim, estimator, planner, wbc) and whose leaves replace
// keys of those files. Strict: an overlay key that the base file does not have, or a mapping where the base
// has a value (or the reverse), is a ConfigError naming the profile file and the key. Profiles compose in
// order (a later profile's leaf wins).
//
// One implementation for every tool: a process installs its profiles once at start-up (setActiveProfiles),
// and StrictNode::loadFile applies them to every <stem>.yaml it reads, so every configuration loader of every
// service and tool sees the same overlaid values without knowing about profiles.
#include <memory>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace mft::config {

// The configuration files a profile may change.
const std::vector<std::string>& profileStems();

class ProfileSet {
 public:
  ProfileSet();
  ProfileSet(const ProfileSet&);
  ProfileSet& operator=(const ProfileSet&);
  ProfileSet(ProfileSet&&) noexcept;
  ProfileSet& operator=(ProfileSet&&) noexcept;
  ~ProfileSet();

  // Reads <config_dir>/profiles/<name>.yaml for each name, in order; throws ConfigError if a file is missing,
  // is not YAML, has a top-level key that is not a profile stem, or a name is given twice.
  static ProfileSet load(const std::string& config_dir, const std::vector<std::string>& names);

  bool empty() const;
  const std::vector<std::string>& names() const;
  // The names joined by ", " ("" when empty), for summaries and messages.
  std::string describe() const;
  // True if some profile changes the file with this stem.
  bool touches(const std::string& stem) const;
  // The overlaid YAML text of `base_text` (the file `stem`.yaml); throws ConfigError on a strictness violation.
  std::string applyToText(const std::string& stem, const std::string& base_text, const std::string& origin) const;
  // Checks every overlay against the base files of `config_dir` (all keys exist, kinds match).
  void check(const std::string& config_dir) const;

  struct Impl;  // yaml-cpp nodes; public for the loader in strict_yaml.cpp
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Applies the profiles' sections for `stem` to `base` (a parsed <stem>.yaml) in place, in order.
void applyProfiles(const ProfileSet& profiles, const std::string& stem, YAML::Node* base, const std::string& origin);

// The profiles that StrictNode::loadFile applies in this process (empty by default). Set once by a main()
// before it loads its configuration.
void setActiveProfiles(ProfileSet profiles);
const ProfileSet& activeProfiles();

// Installs `profiles` for its lifetime and restores the previous set afterwards (tools that load several
// configurations in one process, tests).
class ScopedProfiles {
 public:
  explicit ScopedProfiles(ProfileSet profiles);
  ~ScopedProfiles();
  ScopedProfiles(const ScopedProfiles&) = delete;
  ScopedProfiles& operator=(const ScopedProfiles&) = delete;

 private:
  ProfileSet previous_;
};

// The profile stem of a configuration file path ("wbc" for ".../wbc.yaml"), or "" if it is not one.
std::string profileStemOf(const std::string& path);

// Splits repeated --profile values, each possibly a comma-separated list, into names (empty items dropped).
std::vector<std::string> splitProfileNames(const std::vector<std::string>& values);

}  // namespace mft::config
