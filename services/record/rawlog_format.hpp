#pragma once
// The mft rawlog format (docs/guide/recording.md, docs/reference/mrpt.md): an MRPT observations-only rawlog ("format #2") whose
// first object is a CObservationComment holding the run's metadata as YAML, followed by standard MRPT
// observations, one or more per DDS message:
//   CObservationRawDAQ for every topic (AIN_double: the channels, channel 0 = tick or seq; schema 2 adds the
//   exact 64-bit integers in AIN_32bits and the text fields in AIN_8bits); CObservationIMU for the torso IMU
//   (`imu`) and, as a derived "virtual INS" view, the estimated floating base (`base_est`).
// Observation timestamps are the simulator's clock: time_base_unix_ns + stamp_ns (100 ns resolution).
// The layout is built once from each message's fields (generated from the IDL, rawlog_layout.hpp): a topic
// without a hand-written presentation gets one label with every field. Schema 1 files (integers as doubles
// only, no text) still read. Never reorder channels without bumping kSchemaVersion.
#include <mrpt/obs/CObservation.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "idl/msg_types.hpp"
#include "mft_rawlog_topics.hpp"

namespace mft::rawlog {

constexpr int kSchemaVersion = 2;        // written
constexpr int kOldestSchemaVersion = 1;  // read: 1 (before exact integers and text) and 2
constexpr const char* kFormatName = "mft-rawlog";

// The recorded topics (Topic, kNumTopics, the Message variant, hasTick, topicName, parseTopic) are generated
// from the topic registry: idl/topics.yaml's rows with record: true, numbered by their rawlog_id
// (mft_rawlog_topics.hpp, idl/gen_topics.py). The messages of one timestamp are written in that order.
inline Topic topicOf(const Message& m) { return static_cast<Topic>(m.index()); }
Message emptyMessage(Topic t);  // a default-constructed message of the topic
// tick (or seq for events) and stamp_ns of a message (0 for events).
std::uint64_t tickOf(const Message& m);
std::uint64_t stampOf(const Message& m);

enum class LabelClass { RawDaq, Imu };
struct LabelSpec {
  std::string label;  // the observation's sensorLabel (also the CSV file name)
  Topic topic;
  LabelClass cls;
  std::vector<std::string> columns;  // RawDAQ: AIN_double channels; IMU: the exported fields
  std::vector<std::string> units;
  std::vector<std::string> exact;    // schema 2: the 64-bit integer channels also held exactly in AIN_32bits
  std::vector<std::pair<std::string, std::size_t>> text;  // schema 2: text fields (name, bytes) in AIN_8bits
  std::string description;
};
// Every label, in writing order (the labels of one topic are contiguous).
const std::vector<LabelSpec>& labels();
int labelIndex(const std::string& label);  // -1 if unknown
// The label indices of one topic, in writing order.
const std::vector<int>& topicLabels(Topic t);

// TTimeStamp <-> UNIX nanoseconds (integer math: never through double, docs/reference/mrpt.md#timestamps).
mrpt::Clock::time_point toMrptTime(std::int64_t unix_ns);
std::int64_t fromMrptTime(mrpt::Clock::time_point t);

// Preallocated observations, one per label, reused for every message (the writer never allocates per tick).
class ObservationEncoder {
 public:
  ObservationEncoder();
  // Fills the observations of `m`'s topic with its content stamped `unix_ns`; returns their label indices.
  const std::vector<int>& encode(const Message& m, std::int64_t unix_ns);
  const mrpt::obs::CObservation& observation(int label_index) const { return *obs_[static_cast<std::size_t>(label_index)]; }

 private:
  std::vector<mrpt::obs::CObservation::Ptr> obs_;
};

// Reassembles messages from consecutive observations: a message is complete when every label of its topic
// has been seen with the same timestamp. `time_base_unix_ns` comes from the metadata.
class MessageAssembler {
 public:
  explicit MessageAssembler(std::int64_t time_base_unix_ns) : time_base_ns_(time_base_unix_ns) {}
  // Returns true and sets *out when `obs` completes a message. Unknown labels are ignored (counted).
  bool add(const mrpt::obs::CObservation& obs, Message* out, std::int64_t* unix_ns);
  std::uint64_t incomplete() const { return incomplete_; }
  std::uint64_t unknown() const { return unknown_; }

 private:
  struct Partial {
    Message msg;
    std::int64_t unix_ns = 0;
    std::uint32_t seen = 0;  // bit per label position within the topic
    bool active = false;
  };
  std::int64_t time_base_ns_;
  std::array<Partial, kNumTopics> partial_{};
  std::uint64_t incomplete_ = 0, unknown_ = 0;
};

// Values of one observation as named columns (the CSV export): RawDAQ channels, or the IMU fields of the label.
// A 64-bit integer channel is a double here (exact below 2^53); observationCells() writes it exactly.
bool observationValues(const mrpt::obs::CObservation& obs, int label_index, std::vector<double>* values);
// The CSV cells of one observation, each preceded by a comma: the columns (integers exactly when the file holds
// them exactly, doubles at full precision), then the text fields quoted. False if it does not fit the label.
bool observationCells(const mrpt::obs::CObservation& obs, int label_index, std::string* cells);

// ---- metadata ----
struct Metadata {
  std::string format;
  int schema_version = 0;
  std::string created_utc;
  std::string mode;          // lockstep | realtime
  int domain = -1;
  std::string scenario_file, scenario_name, controller;
  std::string robot_checksum;
  std::vector<std::string> profiles;  // configuration profiles in force (config/profiles/), in order
  // The DDS names of the recorded stack: "ros2" (topics rt/mft/<snake>, types mft::msg::dds_::<Name>_,
  // services/runtime/topic_names.hpp); files written before they existed say nothing and read as "plain".
  std::string dds_naming = "plain";
  std::int64_t time_base_unix_ns = 0;  // observation timestamp = time_base + stamp_ns
  int piece = 0;
  std::map<std::string, std::string> config;  // file name (robot.yaml, ..., scenario, terrain/<x>.yaml) -> text
  std::string text;          // the YAML as stored
};
// YAML text of the metadata comment (labels, columns and units included).
std::string metadataYaml(const Metadata& m);
// Parses the comment text; throws std::runtime_error with a clear message if it is not mft metadata.
Metadata parseMetadata(const std::string& text);

}  // namespace mft::rawlog
