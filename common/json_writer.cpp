#include "common/json_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>


namespace mft::config {

std::size_t utf8Length(const std::string& text, std::size_t at) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(at);
  if (lead < 0x80) return 1;
  std::size_t n = 0;
  unsigned min = 0;
  if ((lead & 0xe0) == 0xc0) n = 2, min = 0x80;
  else if ((lead & 0xf0) == 0xe0) n = 3, min = 0x800;
  else if ((lead & 0xf8) == 0xf0) n = 4, min = 0x10000;
  else return 0;
  if (at + n > text.size()) return 0;
  unsigned code = lead & (0x7f >> n);
  for (std::size_t i = 1; i < n; ++i) {
    if ((byte(at + i) & 0xc0) != 0x80) return 0;
    code = (code << 6) | (byte(at + i) & 0x3f);
  }
  // Overlong forms, UTF-16 surrogates and code points past U+10FFFF are not UTF-8.
  if (code < min || (code >= 0xd800 && code <= 0xdfff) || code > 0x10ffff) return 0;
  return n;
}

bool isUtf8(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8Length(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string printableText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto u = static_cast<unsigned char>(text[i]);
    const std::size_t n = u >= 0x80 ? utf8Length(text, i) : (u >= 0x20 && u != 0x7f ? 1 : 0);
    if (n > 0) {
      out.append(text, i, n);
      i += n;
      continue;
    }
    char hex[5];
    std::snprintf(hex, sizeof hex, "\\x%02x", u);
    out += hex;
    ++i;
  }
  return out;
}

std::string jsonEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size() + 8);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80) {  // a whole UTF-8 sequence as it is; a byte that is not one as U+FFFD (JSON is UTF-8)
      const std::size_t n = utf8Length(text, i);
      if (n == 0) out += "\\ufffd";
      else out.append(text, i, n), i += n - 1;
      continue;
    }
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      default:
        if (u < 0x20 || u == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(u));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out;
}

std::string jsonString(const std::string& text) { return "\"" + jsonEscape(text) + "\""; }

std::string jsonNumber(double value, int significant_digits) {
  if (!std::isfinite(value)) return "null";
  char buf[64];
  if (significant_digits != kRoundTrip) {
    std::snprintf(buf, sizeof buf, "%.*g", significant_digits, value);
    return buf;
  }
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

std::string jsonFixed(double value, int decimals) {
  if (!std::isfinite(value)) return "null";
  char buf[352];  // %.Nf of 1e308 has 309 digits before the point
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

void JsonWriter::beforeValue() {
  if (!open_.empty() && open_.back() == '{' && !after_key_)
    throw std::logic_error("JsonWriter: a value inside an object needs a key");
  if (open_.empty() && !out_.empty()) throw std::logic_error("JsonWriter: a second top-level value");
  if (!after_key_ && !first_) out_ += ", ";
  after_key_ = false;
  first_ = false;
}

JsonWriter& JsonWriter::open(char bracket) {
  beforeValue();
  out_ += bracket;
  open_.push_back(bracket);
  first_ = true;
  return *this;
}
JsonWriter& JsonWriter::close(char bracket) {
  if (open_.empty() || open_.back() != bracket || after_key_)
    throw std::logic_error(std::string("JsonWriter: unbalanced close of ") + bracket);
  open_.pop_back();
  out_ += bracket == '{' ? '}' : ']';
  first_ = false;
  return *this;
}
JsonWriter& JsonWriter::key(std::string_view name) {
  if (open_.empty() || open_.back() != '{' || after_key_) throw std::logic_error("JsonWriter: a key outside an object");
  if (!first_) out_ += ", ";
  out_ += jsonString(std::string(name));
  out_ += ": ";
  after_key_ = true;
  return *this;
}
JsonWriter& JsonWriter::value(double v, int significant_digits) { return raw(jsonNumber(v, significant_digits)); }
JsonWriter& JsonWriter::fixed(double v, int decimals) { return raw(jsonFixed(v, decimals)); }
JsonWriter& JsonWriter::value(bool v) { return raw(v ? "true" : "false"); }
JsonWriter& JsonWriter::value(std::string_view text) { return raw(jsonString(std::string(text))); }
JsonWriter& JsonWriter::null() { return raw("null"); }
JsonWriter& JsonWriter::raw(std::string_view json) {
  beforeValue();
  out_ += json;
  return *this;
}
JsonWriter& JsonWriter::numbers(std::initializer_list<double> v, int significant_digits) {
  beginArray();
  for (const double x : v) value(x, significant_digits);
  return endArray();
}
JsonWriter& JsonWriter::numbers(std::string_view name, const double* v, std::size_t n, int significant_digits) {
  key(name);
  beginArray();
  for (std::size_t i = 0; i < n; ++i) value(v[i], significant_digits);
  return endArray();
}

const std::string& JsonWriter::str() const {
  if (!open_.empty()) throw std::logic_error("JsonWriter: an object or array is still open");
  return out_;
}

}  // namespace mft::config
