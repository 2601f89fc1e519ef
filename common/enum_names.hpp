#pragma once
// One table per enum names its values for messages, logs and configuration files; the name of a value, the
// value of a name and the "a, b or c" list in error messages all come from that one table.
//   constexpr config::EnumName<Colour> kColourNames[] = {{Colour::Red, "red"}, {Colour::Blue, "blue"}};
//   nameOf(kColourNames, Colour::Red) == "red";  parseName(kColourNames, "blue", &c) sets c and returns true.
#include <cstddef>
#include <string>

namespace mft::config {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

// The name of `value`, or `unknown` for a value the table does not list.
template <class E, std::size_t N>
const char* nameOf(const EnumName<E> (&table)[N], E value, const char* unknown = "?") {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name;
  return unknown;
}

// Sets *out to the value named `text` and returns true; returns false (and leaves *out) for any other text.
template <class E, std::size_t N>
bool parseName(const EnumName<E> (&table)[N], const std::string& text, E* out) {
  for (const auto& entry : table) {
    if (text == entry.name) {
      *out = entry.value;
      return true;
    }
  }
  return false;
}

// The names joined as "a, b or c" (`last` joins the final two; ", " joins the others).
template <class E, std::size_t N>
std::string nameList(const EnumName<E> (&table)[N], const char* last = " or ") {
  std::string list;
  for (std::size_t i = 0; i < N; ++i) list += (i == 0 ? "" : (i + 1 == N ? last : ", ")) + std::string(table[i].name);
  return list;
}

}  // namespace mft::config
