#include "services/record/rawlog_format.hpp"

#include "services/record/rawlog_layout.hpp"

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <tuple>
#include <utility>


namespace mft::rawlog {

using mrpt::obs::CObservationIMU;
using mrpt::obs::CObservationRawDAQ;

namespace {

constexpr std::int64_t kFiletimeUnixOffset100ns = 116444736000000000LL;  // 1601-01-01 -> 1970-01-01

std::vector<LabelSpec> makeLabels() {
  std::vector<LabelSpec> specs;
  for (const auto& layout : layout::table()) {
    LabelSpec s{layout.label, layout.topic, layout.cls, {}, {}, {}, {}, layout.description};
    for (const auto& c : layout.channels) {
      s.columns.push_back(c.column);
      s.units.push_back(c.unit);
    }
    for (const auto& f : layout.imu)
      if (!f.column.empty()) {
        s.columns.push_back(f.column);
        s.units.push_back(f.unit);
      }
    for (const auto ci : layout.exact) s.exact.push_back(layout.channels[ci].column);
    for (const auto& t : layout.text) {  // named after the field, unless a channel has that name (config_change's key)
      std::string name = layout::fieldsOf(layout.topic).fields[t.field].name;
      if (std::find(s.columns.begin(), s.columns.end(), name) != s.columns.end()) name += "_text";
      s.text.emplace_back(name, t.bytes);
    }
    specs.push_back(std::move(s));
  }
  return specs;
}

template <std::size_t... I>
std::array<Message, kNumTopics> makeEmpty(std::index_sequence<I...>) {
  return {Message(std::in_place_index<I>)...};
}

// The variant index of a message type.
template <class T, std::size_t I = 0>
constexpr std::size_t topicIndex() {
  if constexpr (std::is_same_v<T, std::variant_alternative_t<I, Message>>) return I;
  else return topicIndex<T, I + 1>();
}
// Events (commands, pushes, live changes, verdicts) carry a sequence number instead of a tick, and are stamped
// on arrival.
template <class T>
constexpr bool kIsEvent = !hasTick(static_cast<Topic>(topicIndex<T>()));

void setStamp(Message* m, std::uint64_t stamp_ns) {
  std::visit(
      [stamp_ns](auto& x) {
        if constexpr (!kIsEvent<std::decay_t<decltype(x)>>) x.stamp_ns(stamp_ns);
      },
      *m);
}

}  // namespace

Message emptyMessage(Topic t) {
  static const auto empty = makeEmpty(std::make_index_sequence<kNumTopics>());
  return empty[static_cast<std::size_t>(t)];
}

std::uint64_t tickOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        if constexpr (kIsEvent<std::decay_t<decltype(x)>>) return x.seq();
        else return x.tick();
      },
      m);
}

std::uint64_t stampOf(const Message& m) {
  return std::visit(
      [](const auto& x) -> std::uint64_t {
        if constexpr (kIsEvent<std::decay_t<decltype(x)>>) return 0;
        else return x.stamp_ns();
      },
      m);
}

const std::vector<LabelSpec>& labels() {
  static const std::vector<LabelSpec> l = makeLabels();
  return l;
}

int labelIndex(const std::string& label) {
  const auto& l = labels();
  for (std::size_t i = 0; i < l.size(); ++i)
    if (l[i].label == label) return static_cast<int>(i);
  return -1;
}

const std::vector<int>& topicLabels(Topic t) {
  static const auto table = [] {
    std::array<std::vector<int>, kNumTopics> a;
    const auto& l = labels();
    for (std::size_t i = 0; i < l.size(); ++i) a[static_cast<std::size_t>(l[i].topic)].push_back(static_cast<int>(i));
    return a;
  }();
  return table[static_cast<std::size_t>(t)];
}

mrpt::Clock::time_point toMrptTime(std::int64_t unix_ns) {
  return mrpt::Clock::time_point(mrpt::Clock::duration(unix_ns / 100 + kFiletimeUnixOffset100ns));
}
std::int64_t fromMrptTime(mrpt::Clock::time_point t) {
  // A corrupt file's timestamp may be any 64-bit count: saturate instead of overflowing (undefined).
  const auto ticks = static_cast<std::int64_t>(t.time_since_epoch().count());
  std::int64_t since_unix = 0, ns = 0;
  if (__builtin_sub_overflow(ticks, kFiletimeUnixOffset100ns, &since_unix) || __builtin_mul_overflow(since_unix, 100, &ns))
    return (ticks < kFiletimeUnixOffset100ns) ? std::numeric_limits<std::int64_t>::min()
                                                : std::numeric_limits<std::int64_t>::max();
  return ns;
}

ObservationEncoder::ObservationEncoder() {
  for (const auto& l : layout::table()) {
    if (l.cls == LabelClass::RawDaq) {
      auto o = CObservationRawDAQ::Create();
      layout::prepare(l, o.get());
      obs_.push_back(o);
    } else {
      auto o = CObservationIMU::Create();
      o->sensorLabel = l.label;
      obs_.push_back(o);
    }
  }
}

const std::vector<int>& ObservationEncoder::encode(const Message& m, std::int64_t unix_ns) {
  const auto& idx = topicLabels(topicOf(m));
  const auto t = toMrptTime(unix_ns);
  for (int li : idx) {
    const auto& l = layout::table()[static_cast<std::size_t>(li)];
    auto& base = obs_[static_cast<std::size_t>(li)];
    base->timestamp = t;
    if (l.cls == LabelClass::RawDaq) layout::write(l, m, static_cast<CObservationRawDAQ*>(base.get()));
    else layout::write(l, m, static_cast<CObservationIMU*>(base.get()));
  }
  return idx;
}

bool MessageAssembler::add(const mrpt::obs::CObservation& obs, Message* out, std::int64_t* unix_ns) {
  const int li = labelIndex(obs.sensorLabel);
  if (li < 0) {
    ++unknown_;
    return false;
  }
  const auto& l = layout::table()[static_cast<std::size_t>(li)];
  const auto& idx = topicLabels(l.topic);
  std::uint32_t bit = 0;
  for (std::size_t i = 0; i < idx.size(); ++i)
    if (idx[i] == li) bit = 1u << i;
  auto& p = partial_[static_cast<std::size_t>(l.topic)];
  const std::int64_t t = fromMrptTime(obs.timestamp);
  if (!p.active || p.unix_ns != t || (p.seen & bit)) {
    if (p.active) ++incomplete_;  // a message whose labels did not all arrive (a cut file)
    p.msg = emptyMessage(l.topic);
    p.unix_ns = t;
    p.seen = 0;
    p.active = true;
  }
  bool fits = true;
  if (l.cls == LabelClass::RawDaq) {
    const auto* o = dynamic_cast<const CObservationRawDAQ*>(&obs);
    fits = o && layout::read(l, *o, &p.msg);
  } else {
    const auto* o = dynamic_cast<const CObservationIMU*>(&obs);
    if (o) layout::read(l, *o, &p.msg);
    fits = o != nullptr;
  }
  if (!fits) {
    ++unknown_;
    return false;
  }
  p.seen |= bit;
  if (p.seen != (1u << idx.size()) - 1u) return false;
  p.active = false;
  if (hasTick(l.topic)) setStamp(&p.msg, static_cast<std::uint64_t>(t - time_base_ns_));
  *out = p.msg;
  *unix_ns = t;
  return true;
}

bool observationValues(const mrpt::obs::CObservation& obs, int label_index, std::vector<double>* values) {
  const auto& l = layout::table()[static_cast<std::size_t>(label_index)];
  values->clear();
  if (l.cls == LabelClass::RawDaq) {
    const auto* o = dynamic_cast<const CObservationRawDAQ*>(&obs);
    if (!o || (o->AIN_double.size() != l.channels.size() && o->AIN_double.size() != l.schema1_channels)) return false;
    values->assign(o->AIN_double.begin(), o->AIN_double.end());
    return true;
  }
  const auto* o = dynamic_cast<const CObservationIMU*>(&obs);
  if (!o) return false;
  for (const auto& f : l.imu)
    if (!f.column.empty()) values->push_back(o->rawMeasurements[f.index]);
  return true;
}

bool observationCells(const mrpt::obs::CObservation& obs, int label_index, std::string* cells) {
  const auto& l = layout::table()[static_cast<std::size_t>(label_index)];
  if (l.cls == LabelClass::RawDaq) {
    const auto* o = dynamic_cast<const CObservationRawDAQ*>(&obs);
    return o && layout::cells(l, *o, cells);
  }
  std::vector<double> values;
  if (!observationValues(obs, label_index, &values)) return false;
  cells->clear();
  char buf[32];
  for (double v : values) {
    std::snprintf(buf, sizeof buf, ",%.17g", v);
    *cells += buf;
  }
  return true;
}

// ------------------------------------------------------------------------------------------------ metadata
std::string metadataYaml(const Metadata& m) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << kFormatName;
  e << YAML::Key << "schema_version" << YAML::Value << kSchemaVersion;
  e << YAML::Key << "created_utc" << YAML::Value << m.created_utc;
  e << YAML::Key << "mode" << YAML::Value << m.mode;
  e << YAML::Key << "domain" << YAML::Value << m.domain;
  e << YAML::Key << "scenario_file" << YAML::Value << m.scenario_file;
  e << YAML::Key << "scenario_name" << YAML::Value << m.scenario_name;
  e << YAML::Key << "controller" << YAML::Value << m.controller;
  e << YAML::Key << "robot_checksum" << YAML::Value << m.robot_checksum;
  e << YAML::Key << "profiles" << YAML::Value << YAML::Flow << m.profiles;
  e << YAML::Comment("config/profiles/ in force; config below holds the files with them applied");
  e << YAML::Key << "dds_naming" << YAML::Value << m.dds_naming;
  e << YAML::Comment("ros2: topics rt/mft/<snake_case>, types mft::msg::dds_::<Name>_ (docs/guide/interop.md)");
  e << YAML::Key << "time_base_unix_ns" << YAML::Value << m.time_base_unix_ns;
  e << YAML::Comment("observation timestamp = time_base_unix_ns + stamp_ns of the simulator clock");
  e << YAML::Key << "piece" << YAML::Value << m.piece;
  e << YAML::Key << "labels" << YAML::Value << YAML::BeginMap;
  for (const auto& s : labels()) {
    e << YAML::Key << s.label << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "topic" << YAML::Value << topicName(s.topic);
    e << YAML::Key << "class" << YAML::Value
      << (s.cls == LabelClass::RawDaq ? "mrpt::obs::CObservationRawDAQ" : "mrpt::obs::CObservationIMU");
    e << YAML::Key << (s.cls == LabelClass::RawDaq ? "AIN_double" : "fields") << YAML::Value << YAML::Flow << s.columns;
    e << YAML::Key << "units" << YAML::Value << YAML::Flow << s.units;
    if (!s.exact.empty()) {
      e << YAML::Key << "AIN_32bits" << YAML::Value << YAML::Flow << s.exact;
      e << YAML::Comment("these channels exactly: low then high 32 bits of each");
    }
    if (!s.text.empty()) {
      e << YAML::Key << "AIN_8bits" << YAML::Value << YAML::Flow << YAML::BeginMap;
      for (const auto& [name, bytes] : s.text) e << YAML::Key << name << YAML::Value << bytes;
      e << YAML::EndMap << YAML::Comment("text fields: bytes each, NUL-padded, in this order");
    }
    e << YAML::Key << "description" << YAML::Value << s.description;
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  e << YAML::Key << "config" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, text] : m.config) e << YAML::Key << name << YAML::Value << YAML::Literal << text;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

Metadata parseMetadata(const std::string& text) {
  Metadata m;
  m.text = text;
  YAML::Node n;
  try {
    n = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("the metadata comment is not YAML: ") + e.what());
  }
  if (!n.IsMap() || !n["format"] || n["format"].as<std::string>("") != kFormatName)
    throw std::runtime_error("the first object is a comment but not mft-rawlog metadata");
  try {
    m.format = n["format"].as<std::string>();
    m.schema_version = n["schema_version"].as<int>();
    if (m.schema_version < kOldestSchemaVersion || m.schema_version > kSchemaVersion)
      throw std::runtime_error("schema_version " + std::to_string(m.schema_version) + " is not supported (this tool reads " +
                               std::to_string(kOldestSchemaVersion) + " to " + std::to_string(kSchemaVersion) + ")");
    m.created_utc = n["created_utc"].as<std::string>("");
    m.mode = n["mode"].as<std::string>("");
    m.domain = n["domain"].as<int>(-1);
    m.scenario_file = n["scenario_file"].as<std::string>("");
    m.scenario_name = n["scenario_name"].as<std::string>("");
    m.controller = n["controller"].as<std::string>("");
    m.robot_checksum = n["robot_checksum"].as<std::string>("");
    if (n["profiles"] && n["profiles"].IsSequence()) m.profiles = n["profiles"].as<std::vector<std::string>>();
    m.dds_naming = n["dds_naming"].as<std::string>("plain");
    m.time_base_unix_ns = n["time_base_unix_ns"].as<std::int64_t>();
    m.piece = n["piece"].as<int>(0);
    if (n["config"] && n["config"].IsMap())
      for (const auto& kv : n["config"]) m.config[kv.first.as<std::string>()] = kv.second.as<std::string>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("bad mft-rawlog metadata: ") + e.what());
  }
  return m;
}

}  // namespace mft::rawlog
