#include "services/record/rawlog_layout.hpp"

#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

namespace mft::rawlog::layout {

namespace {

template <std::size_t... I>
std::array<FieldTable, kNumTopics> makeTables(std::index_sequence<I...>) {
  return {FieldTable{msg::fields::Of<std::variant_alternative_t<I, Message>>::fields.data(),
                     msg::fields::Of<std::variant_alternative_t<I, Message>>::count}...};
}

// The message inside the variant (the generated accessors want a mutable one; the writers only read).
void* addressOf(const Message& m) {
  return std::visit([](const auto& x) -> void* { return const_cast<std::decay_t<decltype(x)>*>(&x); }, m);
}

template <class T>
T element(const void* base, std::size_t i) {
  T v;
  std::memcpy(&v, static_cast<const unsigned char*>(base) + i * sizeof(T), sizeof(T));
  return v;
}
template <class T>
void setElement(void* base, std::size_t i, T v) {
  std::memcpy(static_cast<unsigned char*>(base) + i * sizeof(T), &v, sizeof(T));
}

double loadDouble(const Field& f, const void* base, std::size_t i) {
  switch (f.kind) {
    case Kind::Bool: return element<bool>(base, i) ? 1.0 : 0.0;
    case Kind::Octet: return element<std::uint8_t>(base, i);
    case Kind::Char: return element<char>(base, i);
    case Kind::Int16: return element<std::int16_t>(base, i);
    case Kind::UInt16: return element<std::uint16_t>(base, i);
    case Kind::Int32: return element<std::int32_t>(base, i);
    case Kind::UInt32: return element<std::uint32_t>(base, i);
    case Kind::Int64: return static_cast<double>(element<std::int64_t>(base, i));
    case Kind::UInt64: return static_cast<double>(element<std::uint64_t>(base, i));
    case Kind::Float: return element<float>(base, i);
    case Kind::Double: return element<double>(base, i);
  }
  return 0.0;
}

// A double read from a file into an integer member: a plain cast is undefined outside the type's range (a
// uint64 near 2^64 comes back from its double as 2^64, and a corrupt file may hold anything), so it saturates.
template <class T>
T saturatingCast(double v) {
  if (std::isnan(v)) return T{0};
  constexpr double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  constexpr double hi = static_cast<double>(std::numeric_limits<T>::max());  // 2^63 or 2^64: rounded up
  if (v <= lo) return std::numeric_limits<T>::lowest();
  if (v >= hi) return std::numeric_limits<T>::max();
  return static_cast<T>(v);
}

// As the schema-1 tables did: a cast to the member's type (flags: != 0), saturated at its range.
void storeDouble(const Field& f, void* base, std::size_t i, double v) {
  switch (f.kind) {
    case Kind::Bool: return setElement<bool>(base, i, v != 0.0);
    case Kind::Octet: return setElement(base, i, saturatingCast<std::uint8_t>(v));
    case Kind::Char: return setElement(base, i, saturatingCast<char>(v));
    case Kind::Int16: return setElement(base, i, saturatingCast<std::int16_t>(v));
    case Kind::UInt16: return setElement(base, i, saturatingCast<std::uint16_t>(v));
    case Kind::Int32: return setElement(base, i, saturatingCast<std::int32_t>(v));
    case Kind::UInt32: return setElement(base, i, saturatingCast<std::uint32_t>(v));
    case Kind::Int64: return setElement(base, i, saturatingCast<std::int64_t>(v));
    case Kind::UInt64: return setElement(base, i, saturatingCast<std::uint64_t>(v));
    case Kind::Float: return setElement(base, i, static_cast<float>(v));
    case Kind::Double: return setElement(base, i, v);
  }
}

const Field& fieldOf(Topic t, std::uint16_t index) { return fieldsOf(t).fields[index]; }

// The observation has this label's shape: schema 2 (every channel, the exact integers, the text) or schema 1
// (doubles only, as many as the label had then).
bool fits(const Label& l, const mrpt::obs::CObservationRawDAQ& o) {
  if (o.AIN_double.size() == l.channels.size())
    return (o.AIN_32bits.empty() || o.AIN_32bits.size() == 2 * l.exact.size()) &&
           (o.AIN_8bits.empty() || o.AIN_8bits.size() == l.text_bytes);
  return l.schema1_channels > 0 && o.AIN_double.size() == l.schema1_channels && o.AIN_32bits.empty() &&
         o.AIN_8bits.empty();
}

Channel channel(Topic t, std::uint16_t field, std::uint16_t element, std::string column, std::string unit) {
  if (field >= fieldsOf(t).count || element >= fieldOf(t, field).count)
    throw std::logic_error("rawlog layout: " + std::string(topicName(t)) + " has no element for column " + column);
  return {std::move(column), std::move(unit), field, element, nullptr};
}

}  // namespace

const FieldTable& fieldsOf(Topic t) {
  static const auto tables = makeTables(std::make_index_sequence<kNumTopics>());
  return tables[static_cast<std::size_t>(t)];
}

int fieldIndex(Topic t, const std::string& name) {
  const auto& ft = fieldsOf(t);
  for (std::size_t i = 0; i < ft.count; ++i)
    if (name == ft.fields[i].name) return static_cast<int>(i);
  return -1;
}

bool isText(const Field& f) { return f.kind == Kind::Char; }
bool isWideInteger(const Field& f) { return f.kind == Kind::Int64 || f.kind == Kind::UInt64; }

Label rawDaq(std::string label, Topic topic, std::string description, const std::vector<Columns>& groups) {
  Label l{std::move(label), topic, LabelClass::RawDaq, std::move(description), {}, {}, {}, {}, 0, nullptr};
  for (const auto& g : groups) {
    const int field = fieldIndex(topic, g.field);
    if (field < 0 || g.units.size() != g.columns.size())
      throw std::logic_error("rawlog layout of " + l.label + ": no field " + g.field + " (or a unit is missing)");
    for (std::size_t i = 0; i < g.columns.size(); ++i)
      l.channels.push_back(channel(topic, static_cast<std::uint16_t>(field), static_cast<std::uint16_t>(g.first + i),
                                   g.columns[i], g.units[i]));
  }
  return l;
}

Label generic(std::string label, Topic topic, std::string description) {
  Label l{std::move(label), topic, LabelClass::RawDaq, std::move(description), {}, {}, {}, {}, 0, nullptr};
  const auto& ft = fieldsOf(topic);
  for (std::uint16_t f = 0; f < ft.count; ++f) {
    if (isText(ft.fields[f])) continue;
    const std::string name = ft.fields[f].name;
    for (std::uint16_t e = 0; e < ft.fields[f].count; ++e)
      l.channels.push_back(channel(topic, f, e, ft.fields[f].count == 1 ? name : name + "_" + std::to_string(e), "-"));
  }
  return l;
}

void finish(std::vector<Label>* labels) {
  std::array<bool, kNumTopics> has_text{};
  for (auto& l : *labels) {
    l.exact.clear();
    for (std::size_t c = 0; c < l.channels.size(); ++c)
      if (l.channels[c].field != kDerived && isWideInteger(fieldOf(l.topic, l.channels[c].field)))
        l.exact.push_back(static_cast<std::uint16_t>(c));
    auto& taken = has_text[static_cast<std::size_t>(l.topic)];
    if (l.cls != LabelClass::RawDaq || taken) continue;
    taken = true;
    const auto& ft = fieldsOf(l.topic);
    for (std::uint16_t f = 0; f < ft.count; ++f)
      if (isText(ft.fields[f])) {
        l.text.push_back({f, l.text_bytes, ft.fields[f].count});
        l.text_bytes += ft.fields[f].count;
      }
  }
}

void prepare(const Label& l, mrpt::obs::CObservationRawDAQ* o) {
  o->AIN_double.assign(l.channels.size(), 0.0);
  o->AIN_32bits.assign(2 * l.exact.size(), 0u);
  o->AIN_8bits.assign(l.text_bytes, 0u);
  o->AIN_channel_count = static_cast<std::uint16_t>(l.channels.size());
  o->AIN_interleaved = true;
  o->sample_rate = hasTick(l.topic) ? 1000.0 : 0.0;
  o->sensorLabel = l.label;
}

void write(const Label& l, const Message& m, mrpt::obs::CObservationRawDAQ* o) {
  const void* base = addressOf(m);
  void* mut = const_cast<void*>(base);
  double* out = o->AIN_double.data();
  for (const auto& c : l.channels)
    *out++ = c.derive ? c.derive(m) : loadDouble(fieldOf(l.topic, c.field), fieldOf(l.topic, c.field).at(mut), c.element);
  std::uint32_t* words = o->AIN_32bits.data();
  for (const auto ci : l.exact) {
    const auto& c = l.channels[ci];
    const auto bits = element<std::uint64_t>(fieldOf(l.topic, c.field).at(mut), c.element);
    *words++ = static_cast<std::uint32_t>(bits & 0xffffffffu);
    *words++ = static_cast<std::uint32_t>(bits >> 32);
  }
  for (const auto& t : l.text) std::memcpy(o->AIN_8bits.data() + t.offset, fieldOf(l.topic, t.field).at(mut), t.bytes);
}

bool read(const Label& l, const mrpt::obs::CObservationRawDAQ& o, Message* m) {
  const bool exact = !o.AIN_32bits.empty(), text = !o.AIN_8bits.empty();
  if (!fits(l, o)) return false;
  void* base = addressOf(*m);
  for (std::size_t c = 0; c < o.AIN_double.size(); ++c)
    if (!l.channels[c].derive) {
      const auto& f = fieldOf(l.topic, l.channels[c].field);
      storeDouble(f, f.at(base), l.channels[c].element, o.AIN_double[c]);
    }
  for (std::size_t k = 0; exact && k < l.exact.size(); ++k) {
    const auto& c = l.channels[l.exact[k]];
    const std::uint64_t bits = o.AIN_32bits[2 * k] | (static_cast<std::uint64_t>(o.AIN_32bits[2 * k + 1]) << 32);
    setElement(fieldOf(l.topic, c.field).at(base), c.element, bits);
  }
  for (const auto& t : l.text)
    if (text) std::memcpy(fieldOf(l.topic, t.field).at(base), o.AIN_8bits.data() + t.offset, t.bytes);
  if (!text && l.schema1) l.schema1(o.AIN_double.data(), m);
  return true;
}

void write(const Label& l, const Message& m, mrpt::obs::CObservationIMU* o) {
  void* base = addressOf(m);
  for (const auto& e : l.imu)
    o->set(e.index, e.derive ? e.derive(m)
                             : e.sign * loadDouble(fieldOf(l.topic, e.field), fieldOf(l.topic, e.field).at(base), e.element));
}

void read(const Label& l, const mrpt::obs::CObservationIMU& o, Message* m) {
  void* base = addressOf(*m);
  for (const auto& e : l.imu)
    if (!e.derive) {
      const auto& f = fieldOf(l.topic, e.field);
      storeDouble(f, f.at(base), e.element, e.sign * o.rawMeasurements[e.index]);
    }
}

bool cells(const Label& l, const mrpt::obs::CObservationRawDAQ& o, std::string* out) {
  const bool exact = !o.AIN_32bits.empty(), text = !o.AIN_8bits.empty();
  if (!fits(l, o)) return false;
  out->clear();
  char buf[40];
  std::size_t next_exact = 0;
  for (std::size_t c = 0; c < l.channels.size(); ++c) {
    if (exact && next_exact < l.exact.size() && l.exact[next_exact] == c) {
      const std::uint64_t bits = o.AIN_32bits[2 * next_exact] | (static_cast<std::uint64_t>(o.AIN_32bits[2 * next_exact + 1]) << 32);
      if (fieldOf(l.topic, l.channels[c].field).kind == Kind::Int64)
        std::snprintf(buf, sizeof buf, ",%" PRId64, static_cast<std::int64_t>(bits));
      else
        std::snprintf(buf, sizeof buf, ",%" PRIu64, bits);
      ++next_exact;
    } else if (c < o.AIN_double.size()) {
      std::snprintf(buf, sizeof buf, ",%.17g", o.AIN_double[c]);
    } else {
      std::snprintf(buf, sizeof buf, ",");  // a channel appended after this file's schema
    }
    *out += buf;
  }
  // A schema-1 observation has no text: the cells show what the reader rebuilds from its channels.
  Message rebuilt = emptyMessage(l.topic);
  if (!text && !l.text.empty()) read(l, o, &rebuilt);
  for (const auto& t : l.text) {
    const auto* bytes = text ? o.AIN_8bits.data() + t.offset
                             : static_cast<const std::uint8_t*>(fieldOf(l.topic, t.field).at(addressOf(rebuilt)));
    *out += ",\"";
    for (std::size_t i = 0; i < t.bytes && bytes[i] != 0; ++i) {
      const char ch = static_cast<char>(bytes[i]);
      *out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    }
    *out += '"';
  }
  return true;
}

}  // namespace mft::rawlog::layout
