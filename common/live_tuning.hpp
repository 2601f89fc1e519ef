#pragma once
// Live tuning (docs/guide/live-tuning.md): the configuration keys a running stack may change (`mft-cmd --set`), and
// the one way a change is judged: the key is set in a copy of the file's YAML and the copy goes through the
// file's own strict loader, so a refused change carries the loader's message.
#include <cstddef>
#include <string>
#include <vector>

namespace mft::config {

// A key that may change while the controller runs: gains and weights, never structure (variant, horizon,
// limits, gait timing). `size` is the number of values (1 or 2: [x, z]).
struct TunableKey {
  const char* stem;  // the configuration file: "wbc" (config/wbc.yaml) or "planner"
  const char* key;   // dotted path inside it
  int size;
};
// The list, in a fixed order: a recording names a key by its index here (rawlog label config_change), so
// entries are only ever appended.
const std::vector<TunableKey>& tunableKeys();
// Index in tunableKeys(), or -1 if the key is not tunable.
int tunableIndex(const std::string& stem, const std::string& key);
// "weights.*, gains.*" style summary of the tunable keys of one file, for messages.
std::string describeTunable(const std::string& stem);

// `yaml_text` with the value at `dotted_key` replaced by (or, if absent, set to) the YAML value `value_yaml`
// ("1e3", "[300, 300]"). A key the file does not have is added, so the strict loader that reads the result
// names it as unknown. Throws ConfigError only for what is not YAML at all or a path through a plain value.
std::string setKey(const std::string& yaml_text, const std::string& dotted_key, const std::string& value_yaml,
                   const std::string& origin);
// The numbers at `dotted_key` of `yaml_text` (a number or a list of numbers); empty if there are none.
std::vector<double> numbersAt(const std::string& yaml_text, const std::string& dotted_key);
// "1000" or "[300, 300]" (shortest text that reads back to the same doubles).
std::string formatNumbers(const double* values, std::size_t count);

// A live change judged: the configuration with it, as the file's strict loader read it, and the value before and
// after.
template <class Config>
struct ConfigOverride {
  Config config;                 // the configuration with the change, as the strict loader read it
  std::string yaml_text;         // its YAML (the base of the next change)
  std::vector<double> value;     // the new value as loaded (1 or 2 numbers)
  std::vector<double> previous;  // the value before the change
};
// The first check of a live change before it is sent (mft-cmd --set): a value for a key with a range in the
// configuration schema (config_schema.hpp) must be plain numbers inside that range ("!!str 5" and "1e308" are
// refused). Anything else is left to the answering service's loader. Throws ConfigError naming `origin`.
void checkLiveValue(const std::string& stem, const std::string& key, const std::string& value_yaml,
                    const std::string& origin);
// One `mft-cmd --set` item, FILE.KEY=VALUE, taken apart: FILE is wbc or planner, KEY and VALUE are non-empty and
// shorter than `max_chars` each (they travel in fixed-size text fields). Throws ConfigError naming the item.
struct SetItem {
  std::string file, key, value;
};
SetItem parseSetItem(const std::string& item, std::size_t max_chars);
// Refuses a `key` of file `stem` that is not tunable live (ConfigError naming the tunable keys).
void requireTunable(const std::string& stem, const std::string& key, const std::string& origin);
// Sets `key` to `value_yaml` in `yaml_text` (named `origin` in messages), reads the result with `load(text,
// origin)` (the file's strict loader: its ConfigError for an unknown key or an invalid value), then requires the
// key to be tunable.
template <class Config, class Load>
ConfigOverride<Config> applyOverride(const std::string& stem, const std::string& yaml_text, const std::string& origin,
                                     const std::string& key, const std::string& value_yaml, Load load) {
  ConfigOverride<Config> out;
  out.yaml_text = setKey(yaml_text, key, value_yaml, origin);
  out.config = load(out.yaml_text, origin);
  requireTunable(stem, key, origin);
  out.value = numbersAt(out.yaml_text, key);
  out.previous = numbersAt(yaml_text, key);
  return out;
}

}  // namespace mft::config
