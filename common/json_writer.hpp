#pragma once
// The one JSON writer of every --json report and exit summary: objects and arrays nest, commas and ": " are
// placed by the writer, strings are escaped (RFC 8259: '"', '\\' and every control character), and numbers
// that are not finite are written as null (NaN and infinities are not JSON). Single line, ", " between items.
// Not for the control loop (it allocates): summaries are written at exit.
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace mft::config {

// The length of the UTF-8 sequence that starts at `at` (1-4), or 0 if the bytes there are not one.
std::size_t utf8Length(const std::string& text, std::size_t at);
bool isUtf8(const std::string& text);
// Text for a one-line message on a terminal or in a log: whole UTF-8 sequences and printable ASCII as they are,
// every other byte (a control character, a byte that is not UTF-8) as \xNN. A message that quotes bytes of a
// foreign file stays readable and valid UTF-8.
std::string printableText(const std::string& text);
// The text of a JSON string without the quotes: '"', '\\' and every control character escaped (RFC 8259),
// so that a scenario name or a file name with a tab or an ESC still gives valid JSON. A whole UTF-8 sequence
// passes; a byte that is not part of one (Latin-1) becomes \ufffd, so the JSON stays UTF-8.
std::string jsonEscape(const std::string& text);
// jsonEscape with the quotes.
std::string jsonString(const std::string& text);

// Significant digits that make a double read back to the same bits (the shortest of 15..17 that does).
constexpr int kRoundTrip = 0;

// A number as JSON: `significant_digits` as %g (kRoundTrip: the shortest exact form), null if not finite.
std::string jsonNumber(double value, int significant_digits = 10);
// A number with a fixed count of decimals (%.Nf), null if not finite.
std::string jsonFixed(double value, int decimals);

class JsonWriter {
 public:
  JsonWriter& beginObject() { return open('{'); }
  JsonWriter& endObject() { return close('{'); }
  JsonWriter& beginArray() { return open('['); }
  JsonWriter& endArray() { return close('['); }
  // Inside an object, the key of the next value.
  JsonWriter& key(std::string_view name);

  JsonWriter& value(double v, int significant_digits = kRoundTrip);
  JsonWriter& fixed(double v, int decimals);
  JsonWriter& value(bool v);
  JsonWriter& value(std::string_view text);
  JsonWriter& value(const char* text) { return value(std::string_view(text)); }
  JsonWriter& value(const std::string& text) { return value(std::string_view(text)); }
  template <class T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, int> = 0>
  JsonWriter& value(T v) {
    return raw(std::is_signed_v<T> ? std::to_string(static_cast<long long>(v))
                                   : std::to_string(static_cast<unsigned long long>(v)));
  }
  JsonWriter& null();
  // A value already rendered as JSON (e.g. another writer's str()).
  JsonWriter& raw(std::string_view json);

  // key + value in one call.
  template <class T>
  JsonWriter& field(std::string_view name, const T& v) {
    key(name);
    return value(v);
  }
  JsonWriter& field(std::string_view name, double v, int significant_digits) {
    key(name);
    return value(v, significant_digits);
  }
  JsonWriter& fixedField(std::string_view name, double v, int decimals) {
    key(name);
    return fixed(v, decimals);
  }
  // An array of numbers (as a value, or as the field `name`).
  JsonWriter& numbers(std::initializer_list<double> v, int significant_digits = kRoundTrip);
  JsonWriter& numbers(std::string_view name, const double* v, std::size_t n, int significant_digits = kRoundTrip);

  // The text; throws std::logic_error if an object or array is still open.
  const std::string& str() const;

 private:
  JsonWriter& open(char bracket);
  JsonWriter& close(char bracket);
  void beforeValue();
  std::string out_;
  std::vector<char> open_;  // '{' or '['
  bool first_ = true;       // no item yet in the innermost container
  bool after_key_ = false;
};

}  // namespace mft::config
