// The rawlog format and the recorder engine without DDS: messages survive encoding, serialization and
// reassembly bit for bit; the recorder writes ticks in order, drops repeats, counts gaps, splits into
// self-contained pieces; the reader reports clean, truncated and foreign files as documented.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <set>

#include "MftMsgsPubSubTypes.h"
#include "services/record/rawlog_reader.hpp"
#include "services/record/recorder.hpp"

using namespace mft;
using namespace mft::rawlog;
namespace fs = std::filesystem;

namespace {

class TempDir {
 public:
  TempDir() : path_(fs::temp_directory_path() / ("mft-rawlog-test-" + std::to_string(getpid()) + "-" + std::to_string(counter_++))) {
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  static inline int counter_ = 0;
  fs::path path_;
};

double rnd(std::mt19937_64& g) { return std::uniform_real_distribution<double>(-10, 10)(g) * std::exp(std::uniform_real_distribution<double>(-20, 5)(g)); }

template <std::size_t N>
void fill(std::array<double, N>& a, std::mt19937_64& g) {
  for (auto& v : a) v = rnd(g);
}

// One tick of every tick topic with random full-precision contents.
std::vector<Message> tickMessages(std::uint64_t k, std::mt19937_64& g) {
  const std::uint64_t stamp = k * 1'000'000;
  msg::GroundTruth gt;
  gt.tick(k), gt.stamp_ns(stamp), fill(gt.q(), g), fill(gt.qd(), g), fill(gt.contact_force(), g), fill(gt.lti(), g);
  msg::SensorData sd;
  sd.tick(k), sd.stamp_ns(stamp), fill(sd.actuated_pos(), g), fill(sd.actuated_vel(), g), fill(sd.passive_pos(), g);
  fill(sd.passive_vel(), g), fill(sd.sea_torque(), g), sd.gyro_pitch_rate(rnd(g)), fill(sd.accel(), g);
  sd.contact({k % 2 == 0, k % 3 == 0});
  msg::RobotState rs;
  rs.tick(k), rs.stamp_ns(stamp), fill(rs.q(), g), fill(rs.qd(), g), rs.contact({true, k % 2 == 1});
  msg::Reference rf;
  rf.tick(k), rf.stamp_ns(stamp), rf.step_index(k / 300), rf.phase(rnd(g)), rf.stance_leg(-1);
  rf.foot_in_stance({true, false}), fill(rf.base_z(), g), fill(rf.base_pitch(), g), fill(rf.foot_pos(), g);
  fill(rf.foot_vel(), g), fill(rf.foot_acc(), g), fill(rf.base_x(), g), rf.hold_base_x(k % 2 == 0);
  msg::JointCommand jc;
  jc.tick(k), jc.stamp_ns(stamp), jc.seq(k + 1), fill(jc.tau(), g), jc.mode(k % 5 == 0 ? 1 : 0);
  msg::WbcDiagnostics wd;
  wd.tick(k), wd.stamp_ns(stamp), wd.solve_time_us(rnd(g)), wd.tick_time_us(rnd(g)), wd.iterations(7), wd.status(0);
  wd.active_constraints(3), wd.slack_norm(rnd(g)), fill(wd.task_error(), g), fill(wd.lti(), g), fill(wd.raci(), g);
  wd.safety_events(2), wd.holding(false), wd.damping(true);
  return {gt, sd, rs, rf, jc, wd};
}

Metadata testMetadata() {
  Metadata m;
  m.mode = "lockstep";
  m.scenario_name = "unit";
  m.controller = "mft";
  m.config["robot.yaml"] = "a: 1\n";
  return m;
}

std::vector<Message> readAll(RawlogReader& r) {
  MessageAssembler a(r.metadata().time_base_unix_ns);
  std::vector<Message> out;
  mrpt::obs::CObservation::Ptr obs;
  Message m;
  std::int64_t t;
  while (r.next(&obs))
    if (a.add(*obs, &m, &t)) out.push_back(m);
  return out;
}

}  // namespace

TEST(RawlogFormat, LabelsAreUniqueAndEveryTickTopicHasATickChannel) {
  std::set<std::string> seen;
  for (const auto& l : labels()) {
    EXPECT_TRUE(seen.insert(l.label).second) << l.label;
    EXPECT_EQ(l.columns.size(), l.units.size()) << l.label;
    if (hasTick(l.topic) && l.cls == LabelClass::RawDaq) {
      EXPECT_EQ(l.columns.front(), "tick");
    }
  }
  for (std::size_t t = 0; t < kNumTopics; ++t) EXPECT_FALSE(topicLabels(static_cast<Topic>(t)).empty());
}

TEST(RawlogFormat, TimestampsUseIntegerMath) {
  const std::int64_t ns = 1'700'000'000'123'456'700LL;
  EXPECT_EQ(fromMrptTime(toMrptTime(ns)), ns);
  EXPECT_NEAR(mrpt::Clock::toDouble(toMrptTime(ns)), 1'700'000'000.1234567, 1e-6);
}

TEST(RawlogRecorder, WritesEveryTickInOrderBitExactAndDropsRepeats) {
  TempDir dir;
  RecorderOptions opt;
  opt.output = dir.file("run.rawlog");
  opt.metadata = testMetadata();
  std::mt19937_64 g(42);
  std::vector<Message> sent;
  {
    Recorder rec(opt);
    rec.start();
    std::optional<Message> held;
    for (std::uint64_t k = 0; k < 500; ++k) {
      const auto msgs = tickMessages(k, g);
      // Arrival order as in a stack: the diagnostics of tick k come after the next tick's ground truth.
      rec.push(msgs[0]);
      if (held) rec.push(*held);
      for (std::size_t i = 1; i < 5; ++i) rec.push(msgs[i]);
      held = msgs[5];
      if (k == 0)
        for (const auto& m : msgs) rec.push(m);  // the start-up re-send of tick 0
      sent.insert(sent.end(), msgs.begin(), msgs.end());
    }
    rec.push(*held);
    rec.stop();
    const auto s = rec.stats();
    for (std::size_t t = 0; t < 6; ++t) {
      EXPECT_EQ(s.topics[t].written, 500u);
      EXPECT_EQ(s.topics[t].tick_gaps, 0u);
      EXPECT_EQ(s.topics[t].repeated, 1u);
    }
  }
  RawlogReader r(opt.output);
  EXPECT_EQ(r.metadata().scenario_name, "unit");
  EXPECT_EQ(r.metadata().config.at("robot.yaml"), "a: 1\n");
  const auto got = readAll(r);
  EXPECT_EQ(r.end(), RawlogReader::End::Clean) << r.endMessage();
  ASSERT_EQ(got.size(), 3000u);
  // In file order: by stamp, then topic; every message equal to what was sent (operator== of the types).
  std::map<std::pair<std::uint64_t, std::size_t>, Message> by_key;
  for (const auto& m : sent) by_key.emplace(std::make_pair(tickOf(m), m.index()), m);
  std::uint64_t prev_stamp = 0;
  for (const auto& m : got) {
    EXPECT_GE(stampOf(m), prev_stamp);
    prev_stamp = stampOf(m);
    EXPECT_TRUE(by_key.at({tickOf(m), m.index()}) == m) << topicName(topicOf(m)) << " tick " << tickOf(m);
  }
  EXPECT_TRUE(fs::exists(sidecarName(opt.output)));
}

TEST(RawlogRecorder, CountsGapsAndSplitsIntoSelfContainedPieces) {
  TempDir dir;
  RecorderOptions opt;
  opt.output = dir.file("split.rawlog");
  opt.metadata = testMetadata();
  opt.split_s = 0.1;
  std::mt19937_64 g(7);
  Recorder rec(opt);
  rec.start();
  for (std::uint64_t k = 0; k < 350; ++k) {
    if (k == 100) continue;  // a lost tick
    for (const auto& m : tickMessages(k, g)) rec.push(m);
  }
  rec.stop();
  const auto s = rec.stats();
  EXPECT_EQ(s.topics[0].tick_gaps, 1u);
  ASSERT_EQ(s.pieces.size(), 4u);  // 0-99, 101-199, 200-299, 300-349 (a piece ends only between ticks)
  EXPECT_EQ(s.pieces[1], dir.file("split.part001.rawlog"));
  std::size_t total = 0;
  for (const auto& p : s.pieces) {
    RawlogReader r(p);  // each piece starts with the metadata
    total += readAll(r).size();
    EXPECT_EQ(r.end(), RawlogReader::End::Clean);
  }
  EXPECT_EQ(total, 349u * 6u);
}

TEST(RawlogReader, TruncatedFileReadsUpToTheLastWholeRecord) {
  TempDir dir;
  RecorderOptions opt;
  opt.output = dir.file("t.rawlog");
  opt.metadata = testMetadata();
  std::mt19937_64 g(3);
  {
    Recorder rec(opt);
    rec.start();
    for (std::uint64_t k = 0; k < 2000; ++k)
      for (const auto& m : tickMessages(k, g)) rec.push(m);
    rec.stop();
  }
  const auto size = fs::file_size(opt.output);
  std::ifstream in(opt.output, std::ios::binary);
  std::string bytes(size * 6 / 10, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::ofstream(dir.file("cut.rawlog"), std::ios::binary) << bytes;
  RawlogReader r(dir.file("cut.rawlog"));
  const auto got = readAll(r);
  EXPECT_EQ(r.end(), RawlogReader::End::Truncated) << r.endMessage();
  EXPECT_GT(got.size(), 6000u);
  EXPECT_LT(got.size(), 12000u);
}

// Independent of gzread: how many bytes raw inflate decodes from a (possibly cut) gzip file.
std::size_t inflatableBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string src((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  z_stream zs{};
  inflateInit2(&zs, 16 + MAX_WBITS);
  zs.next_in = reinterpret_cast<Bytef*>(src.data());
  zs.avail_in = static_cast<uInt>(src.size());
  std::vector<unsigned char> out(1 << 16);
  std::size_t total = 0;
  for (int ret = Z_OK; ret == Z_OK;) {
    zs.next_out = out.data();
    zs.avail_out = static_cast<uInt>(out.size());
    ret = inflate(&zs, Z_NO_FLUSH);
    total += out.size() - zs.avail_out;
    if (ret == Z_BUF_ERROR && zs.avail_in == 0) break;  // the cut: no more input
  }
  inflateEnd(&zs);
  return total;
}

// A recording cut by a crash or a full disk: every whole tick that zlib can decode is read back. (The reader
// used to stop at zlib's "unexpected end of file" flag, raised while up to 512 kB of decoded data still sat in
// zlib's buffer: about 0.1 s of a real recording was lost behind the last flush.)
TEST(RawlogReader, CutFileGivesBackEveryTickBeforeTheCut) {
  TempDir dir;
  RecorderOptions opt;
  opt.output = dir.file("t.rawlog");
  opt.metadata = testMetadata();
  constexpr std::uint64_t kTicks = 3000;
  std::mt19937_64 g(5);
  {
    Recorder rec(opt);
    rec.start();
    for (std::uint64_t k = 0; k < kTicks; ++k)
      for (const auto& m : tickMessages(k, g)) rec.push(m);
    rec.stop();
  }
  const std::size_t full_raw = inflatableBytes(opt.output);
  std::ifstream in(opt.output, std::ios::binary);
  std::string bytes(fs::file_size(opt.output) * 7 / 10, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::ofstream(dir.file("cut.rawlog"), std::ios::binary) << bytes;
  const std::size_t cut_raw = inflatableBytes(dir.file("cut.rawlog"));
  RawlogReader r(dir.file("cut.rawlog"));
  const auto got = readAll(r);
  EXPECT_EQ(r.end(), RawlogReader::End::Truncated) << r.endMessage();
  // Every tick has the same serialized size: the decodable prefix holds this many whole ticks (the metadata
  // comment at the start makes the estimate at most one tick high).
  const double ticks_in_prefix = static_cast<double>(kTicks) * static_cast<double>(cut_raw) / static_cast<double>(full_raw);
  const double ticks_read = static_cast<double>(got.size()) / 6.0;
  EXPECT_GT(ticks_read, ticks_in_prefix - 2.0) << "decodable " << cut_raw << " of " << full_raw << " bytes";
  EXPECT_LE(ticks_read, ticks_in_prefix + 1.0);
}

TEST(RawlogReader, RefusesFilesThatAreNotMftRawlogs) {
  TempDir dir;
  std::ofstream(dir.file("text.rawlog")) << "time,x\n0,1\n";
  EXPECT_THROW(RawlogReader r(dir.file("text.rawlog")), NotMftRawlog);
  EXPECT_THROW(RawlogReader r(dir.file("missing.rawlog")), NotMftRawlog);
  std::ofstream(dir.file("empty.rawlog")).close();
  EXPECT_THROW(RawlogReader r(dir.file("empty.rawlog")), NotMftRawlog);
  try {
    Metadata m = testMetadata();
    std::string y = metadataYaml(m);
    y.replace(y.find("schema_version: 1"), 17, "schema_version: 2");
    parseMetadata(y);
    FAIL() << "schema 2 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("schema_version 2 is not supported"), std::string::npos) << e.what();
  }
}

// A field added to a topic must be added to the rawlog format (and the schema version bumped), or replays
// would silently lose it: the serialized sizes pin the message layouts the format knows.
TEST(RawlogFormat, KnowsEveryFieldOfEveryTopic) {
  EXPECT_EQ(msg::GroundTruthPubSubType().m_typeSize, 244u) << "GroundTruth changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::SensorDataPubSubType().m_typeSize, 208u) << "SensorData changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::RobotStatePubSubType().m_typeSize, 200u) << "RobotState changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::ReferencePubSubType().m_typeSize, 216u) << "Reference changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::JointCommandPubSubType().m_typeSize, 64u) << "JointCommand changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::WbcDiagnosticsPubSubType().m_typeSize, 152u) << "WbcDiagnostics changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::OperatorCommandPubSubType().m_typeSize, 32u) << "OperatorCommand changed: update rawlog_format.cpp";
  EXPECT_EQ(msg::DisturbancePubSubType().m_typeSize, 40u) << "Disturbance changed: update rawlog_format.cpp";
}
