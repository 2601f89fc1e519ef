#pragma once
// The one table of every numeric configuration key: its physical range and unit. Every strict loader
// (strict_yaml.hpp) checks the numbers it read against it when the file is finished, so the config check,
// live tuning (which runs the file's loader) and the generated reference (docs/reference/config-reference.md) agree.
// Ranges are what is physically sane for a legged robot of this kind, never tuned values.
#include <string>
#include <vector>

namespace mft::config {

struct KeyRange {
  const char* stem;  // the configuration kind: robot, wbc, planner, estimator, sim, mft_space, scenario, terrain
  const char* key;   // dotted path; a list of mappings is written name[] ("commands[].at_s")
  double lo;
  double hi;
  const char* unit;  // "-" when dimensionless
  const char* meaning;
};

const std::vector<KeyRange>& configSchema();
// The entry of `stem` for `key` (list indices "[3]" read as "[]"), or nullptr.
const KeyRange* findKeyRange(const std::string& stem, const std::string& key);
// "must lie in [lo, hi] unit (got v)" if v is outside the entry's range, else "".
std::string rangeViolation(const KeyRange& range, double v);
// The reference table of docs/reference/config-reference.md (Markdown), generated from configSchema().
std::string schemaMarkdown();

}  // namespace mft::config
