#pragma once
// mft-space's JSON: the shared writer (common/json_writer.hpp), numbers at 10 significant digits.
#include "common/json_writer.hpp"

namespace mft::tools {

using config::JsonWriter;
constexpr int kDigits = 10;

}  // namespace mft::tools
