#pragma once
// The generic rawlog layout: how a message's fields (the tables idl/gen_topics.py generates from the IDL)
// become the channels of its labels, and the one writer and one reader of a sample through it. Built once at
// start; per sample the writer and reader only index into these tables (nothing is allocated).
//   AIN_double: one channel per element of each numeric field (or a derived value, e.g. a key's index).
//   AIN_32bits (schema 2): each 64-bit integer channel again, exactly, as its low then high 32-bit word.
//   AIN_8bits  (schema 2): the topic's text fields, each at its full declared length, in field order.
// A schema-1 observation has neither of the last two: its integers are read from the doubles, and a label's
// `schema1` hook rebuilds the text that schema 1 kept in another form. Channels are only ever appended to a label:
// a schema-1 observation may have fewer (`schema1_channels`); the fields of the missing ones stay default.
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRawDAQ.h>

#include <cstdint>
#include <string>
#include <vector>

#include "mft_msgs_fields.h"
#include "services/record/rawlog_format.hpp"

namespace mft::rawlog::layout {

using msg::fields::Field;
using msg::fields::Kind;

struct FieldTable {
  const Field* fields;
  std::size_t count;
};
// The generated field table of a topic's message.
const FieldTable& fieldsOf(Topic t);
int fieldIndex(Topic t, const std::string& name);  // -1 if the message has no such field
bool isText(const Field& f);
bool isWideInteger(const Field& f);  // 64-bit: not exact as a double above 2^53

constexpr std::uint16_t kDerived = 0xffff;

struct Channel {  // one AIN_double channel
  std::string column, unit;
  std::uint16_t field = kDerived, element = 0;
  double (*derive)(const Message&) = nullptr;  // field == kDerived: written from this, not read back
};
struct ImuEntry {  // one CObservationIMU value
  mrpt::obs::TIMUDataIndex index;
  std::string column, unit;  // column empty: stored for MRPT tools, not exported
  std::uint16_t field = kDerived, element = 0;
  double sign = 1.0;
  double (*derive)(const Message&) = nullptr;  // field == kDerived: a derived view, not read back
};
struct TextField {
  std::uint16_t field;
  std::size_t offset, bytes;
};
struct Label {
  std::string label;
  Topic topic;
  LabelClass cls;
  std::string description;
  std::vector<Channel> channels;     // RawDaq
  std::vector<ImuEntry> imu;         // Imu
  std::vector<std::uint16_t> exact;  // channels of 64-bit integer fields, in AIN_32bits
  std::vector<TextField> text;       // in AIN_8bits
  std::size_t text_bytes = 0;
  void (*schema1)(const double* channels, Message* m) = nullptr;  // a schema-1 observation: rebuild the text
  std::size_t schema1_channels = 0;  // channels are only ever appended: how many schema 1 had (0: all of them)
};

// A run of channels from one field: elements first .. first + columns.size() - 1.
struct Columns {
  const char* field;
  std::vector<std::string> columns, units;
  std::uint16_t first = 0;
};
// A RawDAQ label from named fields; throws std::logic_error if a field or element does not exist.
Label rawDaq(std::string label, Topic topic, std::string description, const std::vector<Columns>& groups);
// The label of a topic without a hand-written one: every numeric field, named after it (arrays `name_i`).
Label generic(std::string label, Topic topic, std::string description);
// Gives each topic's text fields to its first RawDAQ label and fills the exact-integer lists.
void finish(std::vector<Label>* labels);

// Per sample. The observations come preallocated by prepare(); read returns false if the observation does not
// have this label's shape.
void prepare(const Label& l, mrpt::obs::CObservationRawDAQ* o);
void write(const Label& l, const Message& m, mrpt::obs::CObservationRawDAQ* o);
bool read(const Label& l, const mrpt::obs::CObservationRawDAQ& o, Message* m);
void write(const Label& l, const Message& m, mrpt::obs::CObservationIMU* o);
void read(const Label& l, const mrpt::obs::CObservationIMU& o, Message* m);
// observationCells() of a RawDAQ observation.
bool cells(const Label& l, const mrpt::obs::CObservationRawDAQ& o, std::string* out);

}  // namespace mft::rawlog::layout

namespace mft::rawlog::layout {
// Every label in writing order (rawlog_labels.cpp): the hand-written presentation of the topics recorded since
// schema 1 (their label and column names stay what tools and plots know), then a generic label for every other
// topic.
const std::vector<Label>& table();
}  // namespace mft::rawlog::layout
