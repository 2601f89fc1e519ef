#pragma once
// mft-space's JSON: the shared writer (model/config/json_writer.hpp), numbers at 10 significant digits.
#include "model/config/json_writer.hpp"

namespace mft::tools {

using config::JsonWriter;
constexpr int kDigits = 10;

}  // namespace mft::tools
