// The rawlog format and the recorder engine without DDS: messages survive encoding, serialization and
// reassembly bit for bit; the recorder writes ticks in order, drops repeats, counts gaps, splits into
// self-contained pieces; the reader reports clean, truncated and foreign files as documented.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <cstdio>
#include <ctime>
#include <sstream>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <random>
#include <set>
#include <type_traits>

#include "idl/msg_pubsub.hpp"
#include "services/record/rawlog_layout.hpp"
#include "services/record/rawlog_reader.hpp"
#include "services/record/recorder.hpp"
#include "tests/rawlog/rawlog_fixture.hpp"

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

// Options that record to `name` in `dir` with the test metadata.
RecorderOptions testOptions(const TempDir& dir, const std::string& name) {
  RecorderOptions opt;
  opt.output = dir.file(name);
  opt.metadata = testMetadata();
  return opt;
}

// Records ticks 0 .. ticks-1 of tickMessages (random contents seeded with `seed`), every message once, in order.
void recordTicks(const RecorderOptions& opt, std::uint64_t ticks, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  Recorder rec(opt);
  rec.start();
  for (std::uint64_t k = 0; k < ticks; ++k)
    for (const auto& m : tickMessages(k, g)) rec.push(m);
  rec.stop();
}

std::vector<Message> readAll(RawlogReader& r) { return fixture::readAll(r); }

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
  RecorderOptions opt = testOptions(dir, "run.rawlog");
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
  RecorderOptions opt = testOptions(dir, "split.rawlog");
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
  RecorderOptions opt = testOptions(dir, "t.rawlog");
  recordTicks(opt, 2000, 3);
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
  RecorderOptions opt = testOptions(dir, "t.rawlog");
  constexpr std::uint64_t kTicks = 3000;
  recordTicks(opt, kTicks, 5);
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
    y.replace(y.find("schema_version: 2"), 17, "schema_version: 3");
    parseMetadata(y);
    FAIL() << "schema 3 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("schema_version 3 is not supported"), std::string::npos) << e.what();
  }
}

// A recording says which DDS names its stack used; a file from before the ROS 2 names says nothing and reads as
// "plain" (and is read like any other).
TEST(RawlogFormat, MetadataRecordsTheDdsNamingAndOlderFilesReadAsPlain) {
  Metadata m = testMetadata();
  m.dds_naming = "ros2";
  const std::string text = metadataYaml(m);
  EXPECT_EQ(parseMetadata(text).dds_naming, "ros2");
  std::string older;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("dds_naming:", 0) != 0) older += line + "\n";
  ASSERT_EQ(older.find("dds_naming"), std::string::npos);
  const Metadata parsed = parseMetadata(older);
  EXPECT_EQ(parsed.dds_naming, "plain");
  EXPECT_EQ(parsed.scenario_name, "unit");
}

// Live tuning (docs/guide/live-tuning.md): an applied change goes through the config_change label and comes back with
// its key and value text exactly as sent (schema 2's text channel), tick and time; the key channel still holds the
// key's index in tunableKeys() (-1 when it is not tunable). An observation without the text (schema 1) gets key and
// value back from that index and the numbers, and a key that is not tunable reads back empty, so mft-replay
// cannot mistake it for another.
TEST(RawlogFormat, ConfigChangeRoundTripsThroughItsLabel) {
  msg::ConfigChange c;
  c.seq(77), c.target(msg::CONFIG_TARGET_WBC), c.applied(true), c.at_s(12.0), c.tick(12000), c.stamp_ns(12000000000ULL);
  std::snprintf(c.key().data(), c.key().size(), "gains.swing_foot.kp");
  std::snprintf(c.value().data(), c.value().size(), "[300,250]");
  c.number({300.0, 250.0}), c.count(2);
  ObservationEncoder enc;
  MessageAssembler asm_(0);
  Message out;
  std::int64_t t = 0;
  bool done = false;
  for (int li : enc.encode(c, 5)) done = asm_.add(enc.observation(li), &out, &t);
  ASSERT_TRUE(done);
  const auto& b = std::get<msg::ConfigChange>(out);
  EXPECT_EQ(b.seq(), 77u);
  EXPECT_TRUE(b.applied());
  EXPECT_EQ(b.target(), msg::CONFIG_TARGET_WBC);
  EXPECT_STREQ(b.key().data(), "gains.swing_foot.kp");
  EXPECT_STREQ(b.value().data(), "[300,250]");
  EXPECT_EQ(b.tick(), 12000u);
  EXPECT_EQ(b.at_s(), 12.0);
  EXPECT_EQ(b.count(), 2);
  const int li = labelIndex("config_change");
  auto schema1 = [&] {  // the observation as schema 1 wrote it: channels only
    auto o = mrpt::obs::CObservationRawDAQ::Create();
    *o = static_cast<const mrpt::obs::CObservationRawDAQ&>(enc.observation(li));
    o->AIN_32bits.clear();
    o->AIN_8bits.clear();
    return o;
  };
  ASSERT_TRUE(asm_.add(*schema1(), &out, &t));
  EXPECT_STREQ(std::get<msg::ConfigChange>(out).key().data(), "gains.swing_foot.kp");
  EXPECT_STREQ(std::get<msg::ConfigChange>(out).value().data(), "[300, 250]");
  std::snprintf(c.key().data(), c.key().size(), "variant");  // not tunable: index -1
  for (int l : enc.encode(c, 6)) done = asm_.add(enc.observation(l), &out, &t);
  ASSERT_TRUE(done);
  EXPECT_STREQ(std::get<msg::ConfigChange>(out).key().data(), "variant");
  std::vector<double> v;
  ASSERT_TRUE(observationValues(enc.observation(li), li, &v));
  EXPECT_EQ(v[3], -1.0);
  ASSERT_TRUE(asm_.add(*schema1(), &out, &t));
  EXPECT_STREQ(std::get<msg::ConfigChange>(out).key().data(), "");
}

// ------------------------------------------------------------------------------ bad input (issue 16, part 3)
namespace {

// A small real recording, decompressed: the base for crafted files.
std::string recordedBytes(const TempDir& dir) {
  RecorderOptions opt = testOptions(dir, "base.rawlog");
  recordTicks(opt, 20, 7);
  std::string raw;
  gzFile f = gzopen(opt.output.c_str(), "rb");
  char buf[65536];
  for (int n; (n = gzread(f, buf, sizeof buf)) > 0;) raw.append(buf, static_cast<std::size_t>(n));
  gzclose(f);
  return raw;
}

void writeGzip(const std::string& path, const std::string& bytes) {
  gzFile f = gzopen(path.c_str(), "wb6");
  ASSERT_TRUE(f);
  ASSERT_EQ(gzwrite(f, bytes.data(), static_cast<unsigned>(bytes.size())), static_cast<int>(bytes.size()));
  gzclose(f);
}

void putU32(std::string* bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*bytes)[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xffu);
}
std::uint32_t getU32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)])) << (8 * i);
  return v;
}

// The metadata comment's text length (right after the class name and the version byte) set to ~4 GiB: a
// valid gzip whose payload declares a huge object.
std::string hugeCommentFile(const TempDir& dir) {
  std::string raw = recordedBytes(dir);
  const std::string cls = "mrpt::obs::CObservationComment";
  EXPECT_EQ(raw.compare(1, cls.size(), cls), 0);
  putU32(&raw, 1 + cls.size() + 1, 0xFFFFFFF0u);
  const std::string path = dir.file("huge-comment.rawlog");
  writeGzip(path, raw);
  return path;
}

// The AIN_8bits count of the first RawDAQ observation set to ~4 G elements.
std::string hugeVectorFile(const TempDir& dir) {
  std::string raw = recordedBytes(dir);
  const std::string cls = "mrpt::obs::CObservationRawDAQ";
  const std::size_t at = raw.find(static_cast<char>(0x80 | cls.size()) + cls);
  EXPECT_NE(at, std::string::npos);
  std::size_t p = at + 1 + cls.size() + 1;  // header, name, version
  p += 4 + getU32(raw, p);                  // sensorLabel
  p += 8 + 8;                               // timestamp, sample_rate
  EXPECT_EQ(getU32(raw, p), 0u) << "AIN_8bits is empty in mft rawlogs";
  putU32(&raw, p, 0xFFFFFFF0u);
  const std::string path = dir.file("huge-vector.rawlog");
  writeGzip(path, raw);
  return path;
}

// Offset of the element count of `field` in the first object of class `cls` in a recorded rawlog's bytes,
// walking the layouts MRPT 2.5.8 writes (docs/reference/mrpt.md "What the reader checks").
std::size_t countOffset(const std::string& raw, const std::string& cls, const std::string& field) {
  const std::size_t at = raw.find(static_cast<char>(0x80 | cls.size()) + cls);
  EXPECT_NE(at, std::string::npos) << cls;
  std::size_t p = at + 1 + cls.size() + 1;  // header, name, version
  if (cls == "mrpt::obs::CObservationIMU") {
    const std::string pose = "mrpt::poses::CPose3D";
    EXPECT_EQ(raw.compare(p + 1, pose.size(), pose), 0);
    p += 1 + pose.size() + 1 + 12 * 8 + 1;  // sensorPose: header, name, version 3, 12 doubles, end marker
    p += 31 + 8 + 31 * 8;                   // dataIsPresent, timestamp, rawMeasurements
    EXPECT_EQ(field, "sensorLabel");
    return p;
  }
  const std::vector<std::pair<std::string, std::size_t>> arrays = {
      {"sensorLabel", 1}, {"AIN_8bits", 1}, {"AIN_16bits", 2}, {"AIN_32bits", 4}, {"AIN_float", 4},
      {"AIN_double", 8}, {"AOUT_8bits", 1}, {"AOUT_16bits", 2}, {"AOUT_float", 4}, {"AOUT_double", 8},
      {"DIN", 1}, {"DOUT", 1}, {"CNTRIN_32bits", 4}, {"CNTRIN_double", 8}};
  for (const auto& [name, bytes] : arrays) {
    if (name == field) return p;
    p += 4 + bytes * getU32(raw, p);
    if (name == "sensorLabel") p += 8 + 8;  // timestamp, sample_rate
    if (name == "AIN_double") p += 2 + 1;   // AIN_channel_count, AIN_interleaved
  }
  ADD_FAILURE() << "no field " << field;
  return 0;
}

// Caps this test process's address space at its current size + 1 GiB (soft limit, restored at the end), so
// that a regression allocating what the file declares fails with bad_alloc instead of eating the machine.
class AddressSpaceCap {
 public:
  AddressSpaceCap() {
    getrlimit(RLIMIT_AS, &saved_);
    std::ifstream statm("/proc/self/statm");
    unsigned long long pages = 0;
    statm >> pages;
    rlimit cap = saved_;
    cap.rlim_cur = pages * static_cast<unsigned long long>(sysconf(_SC_PAGESIZE)) + (1ull << 30);
    if (saved_.rlim_max != RLIM_INFINITY) cap.rlim_cur = std::min<rlim_t>(cap.rlim_cur, saved_.rlim_max);
    setrlimit(RLIMIT_AS, &cap);
  }
  ~AddressSpaceCap() { setrlimit(RLIMIT_AS, &saved_); }

 private:
  rlimit saved_{};
};

// CPU time, not wall time: what "fast" means on a loaded machine (a refusal costs milliseconds of CPU;
// allocating and zeroing what the file declares, seconds).
double cpuSecondsSince(std::clock_t t0) { return static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC; }
double childCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct ToolRun {
  int code = -1;
  std::string err;
  double seconds = 0.0;  // CPU
};
// Runs a tool of the build with `args`; stderr captured, stdout discarded; a 4 GiB address-space cap.
ToolRun runTool(const std::string& tool, const std::string& args, const TempDir& dir) {
  const std::string err = dir.file("stderr.txt");
  const std::string cmd = "ulimit -v 4194304; " + std::string(MFT_BIN_DIR) + "/" + tool + " " + args + " > /dev/null 2> " + err;
  const double cpu0 = childCpuSeconds();
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.seconds = childCpuSeconds() - cpu0;  // CPU seconds of the shell and the tool
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

std::size_t lineCount(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

// Item 6: a declared length is bounded before anything is allocated for it; refused at once, with a message
// that says what was declared.
TEST(RawlogBadInput, HugeDeclaredMetadataIsRefusedFastWithoutAllocating) {
  TempDir dir;
  const std::string path = hugeCommentFile(dir);
  AddressSpaceCap cap;
  const std::clock_t t0 = std::clock();
  try {
    RawlogReader r(path);
    FAIL() << "accepted a file declaring a 4 GiB metadata comment";
  } catch (const NotMftRawlog& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("declares 4294967280 elements"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'text'"), std::string::npos) << msg;
  }
  EXPECT_LT(cpuSecondsSince(t0), 0.5);
}

TEST(RawlogBadInput, HugeDeclaredObservationEndsTheReadAsCorruptFast) {
  TempDir dir;
  const std::string path = hugeVectorFile(dir);
  AddressSpaceCap cap;
  const std::clock_t t0 = std::clock();
  RawlogReader r(path);
  const auto got = readAll(r);
  EXPECT_LT(cpuSecondsSince(t0), 0.5);
  EXPECT_EQ(r.end(), RawlogReader::End::Corrupt) << r.endMessage();
  EXPECT_NE(r.endMessage().find("declares 4294967280 elements"), std::string::npos) << r.endMessage();
  EXPECT_NE(r.endMessage().find("AIN_8bits"), std::string::npos) << r.endMessage();
  EXPECT_TRUE(got.empty()) << "the first observation is the damaged one";
}

// Every length field of every object mft-record writes is bounded, the last ones included (the IMU's label
// after its nested pose; the RawDAQ's counter channels after the fields mft rawlogs fill).
TEST(RawlogBadInput, EveryDeclaredLengthOfEveryRecordedClassIsBounded) {
  TempDir dir;
  const std::string raw = recordedBytes(dir);
  for (const auto& [cls, field] : std::vector<std::pair<std::string, std::string>>{
           {"mrpt::obs::CObservationIMU", "sensorLabel"},
           {"mrpt::obs::CObservationRawDAQ", "AOUT_double"},
           {"mrpt::obs::CObservationRawDAQ", "DOUT"},
           {"mrpt::obs::CObservationRawDAQ", "CNTRIN_double"}}) {
    std::string bad = raw;
    const std::size_t at = countOffset(bad, cls, field);
    ASSERT_GT(at, 0u);
    putU32(&bad, at, 0xFFFFFFF0u);
    const std::string path = dir.file("huge-" + field + ".rawlog");
    writeGzip(path, bad);
    AddressSpaceCap cap;
    const std::clock_t t0 = std::clock();
    RawlogReader r(path);
    const auto got = readAll(r);
    EXPECT_LT(cpuSecondsSince(t0), 0.5) << field;
    EXPECT_EQ(r.end(), RawlogReader::End::Corrupt) << field << ": " << r.endMessage();
    EXPECT_NE(r.endMessage().find("declares 4294967280 elements"), std::string::npos) << r.endMessage();
    EXPECT_NE(r.endMessage().find("'" + field + "'"), std::string::npos) << r.endMessage();
  }
}

// The walk ends exactly at each object's end marker: a damaged marker after the last field is found.
TEST(RawlogBadInput, AMissingEndMarkerAfterTheLastFieldIsCorrupt) {
  TempDir dir;
  std::string raw = recordedBytes(dir);
  const std::size_t at = countOffset(raw, "mrpt::obs::CObservationRawDAQ", "CNTRIN_double");
  const std::size_t end = at + 4 + 8 * getU32(raw, at);
  ASSERT_EQ(static_cast<unsigned char>(raw[end]), 0x88u) << "the layout walked here is MRPT's";
  raw[end] = 0x55;
  const std::string path = dir.file("no-end-marker.rawlog");
  writeGzip(path, raw);
  RawlogReader r(path);
  readAll(r);
  EXPECT_EQ(r.end(), RawlogReader::End::Corrupt) << r.endMessage();
  EXPECT_NE(r.endMessage().find("end marker"), std::string::npos) << r.endMessage();
}

TEST(RawlogBadInput, ExportAndReplayRefuseAHugeDeclaredObjectInWellUnderASecond) {
  TempDir dir;
  const std::string path = hugeCommentFile(dir);
  for (const auto& [tool, args] : std::vector<std::pair<std::string, std::string>>{
           {"mft-export", path + " --info"}, {"mft-replay", path + " --through-wbc"}}) {
    const ToolRun r = runTool(tool, args, dir);
    EXPECT_EQ(r.code, 2) << tool << ": " << r.err;
    EXPECT_NE(r.err.find("declares 4294967280 elements"), std::string::npos) << tool << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << tool << ": " << r.err;
    EXPECT_LT(r.seconds, 2.0) << tool << " CPU seconds (process start included)";
  }
  const ToolRun r = runTool("mft-export", hugeVectorFile(dir) + " --info", dir);
  EXPECT_EQ(r.code, 4) << r.err;  // corrupt: exported up to the damage
  EXPECT_NE(r.err.find("AIN_8bits"), std::string::npos) << r.err;
  EXPECT_LT(r.seconds, 2.0);
}

// The recorder stores samples in arrival order; on a loaded machine a JointCommand(k) can arrive before the
// Reference(k) it answers. `mft-replay --through-wbc` pairs them by tick: every command is compared (random
// contents, so the torques themselves differ: the tolerance is set out of the way), none is "unmatched".
TEST(RawlogReplay, ThroughWbcPairsInputsAndCommandsByTickWhateverTheRecordedOrder) {
  TempDir dir;
  RecorderOptions opt = testOptions(dir, "reordered.rawlog");
  for (const char* name : {"robot.yaml", "wbc.yaml", "mft_space.yaml"}) {
    std::ifstream in(std::string(MFT_CONFIG_DIR) + "/" + name);
    std::stringstream text;
    text << in.rdbuf();
    opt.metadata.config[name] = text.str();
  }
  // No reordering window: a sample is written as soon as the writer sees it (what a sample held past the
  // recorder's wall-clock hold on a loaded machine gets).
  opt.reorder_window_ns = 0;
  constexpr std::uint64_t kTicks = 40;
  const auto command = static_cast<std::size_t>(Topic::JointCommand);
  std::mt19937_64 g(11);
  {
    Recorder rec(opt);
    rec.start();
    for (std::uint64_t k = 0; k < kTicks; ++k) {
      auto m = tickMessages(k, g);  // GroundTruth, SensorData, RobotState, Reference, JointCommand, diagnostics
      if (k % 2 == 0) {
        for (const auto& x : m) rec.push(x);
        continue;
      }
      // The command is written before its reference arrives.
      for (std::size_t i : {0, 1, 2, 4, 5}) rec.push(m[i]);
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (rec.stats().topics[command].written < k + 1 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      ASSERT_EQ(rec.stats().topics[command].written, k + 1) << "the recorder did not write JointCommand " << k;
      rec.push(m[3]);
    }
    rec.stop();
  }
  const std::string cmd = std::string(MFT_BIN_DIR) + "/mft-replay " + opt.output +
                          " --through-wbc --tolerance 1e9 --json > " + dir.file("replay.json") + " 2> " +
                          dir.file("replay.err");
  const int status = std::system(cmd.c_str());
  std::stringstream out, err;
  out << std::ifstream(dir.file("replay.json")).rdbuf();
  err << std::ifstream(dir.file("replay.err")).rdbuf();
  const std::string json = out.str();
  ASSERT_TRUE(WIFEXITED(status)) << err.str();
  EXPECT_NE(json.find("\"ticks_compared\": " + std::to_string(kTicks) + ","), std::string::npos) << json << err.str();
  EXPECT_NE(json.find("\"unmatched_commands\": 0,"), std::string::npos) << json << err.str();
}

// Item 12: what a file is when it is not a rawlog, instead of "empty file".
TEST(RawlogBadInput, RefusalsSayWhatTheFileIs) {
  TempDir dir;
  const std::string raw = recordedBytes(dir);
  auto refusal = [](const std::string& path) {
    try {
      RawlogReader r(path);
    } catch (const NotMftRawlog& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  fs::create_directories(dir.file("a-folder"));
  EXPECT_NE(refusal(dir.file("a-folder")).find("is a directory"), std::string::npos) << refusal(dir.file("a-folder"));
  // The first 100 bytes of a real recording.
  {
    std::ifstream in(dir.file("base.rawlog"), std::ios::binary);
    std::string head(100, '\0');
    in.read(head.data(), 100);
    std::ofstream(dir.file("cut100.rawlog"), std::ios::binary) << head;
  }
  const std::string cut = refusal(dir.file("cut100.rawlog"));
  EXPECT_NE(cut.find("truncated header"), std::string::npos) << cut;
  EXPECT_EQ(cut.find("empty file"), std::string::npos) << cut;
  // 100 bytes that are neither gzip nor MRPT.
  std::ofstream(dir.file("junk.rawlog"), std::ios::binary) << std::string(100, 'x');
  const std::string junk = refusal(dir.file("junk.rawlog"));
  EXPECT_NE(junk.find("not an MFT rawlog"), std::string::npos) << junk;
  std::ofstream(dir.file("empty.rawlog")).close();
  EXPECT_NE(refusal(dir.file("empty.rawlog")).find("empty file (0 bytes)"), std::string::npos);
  // The metadata comment cut in the middle (decompressed data ends inside it).
  writeGzip(dir.file("cut-comment.rawlog"), raw.substr(0, 60));
  const std::string cut_comment = refusal(dir.file("cut-comment.rawlog"));
  EXPECT_NE(cut_comment.find("truncated header: the file ends inside the metadata comment"), std::string::npos) << cut_comment;
  // And the tools say the same, on one line.
  const ToolRun r = runTool("mft-export", dir.file("a-folder") + " --info", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
}

// Item 5: output folders that cannot be folders are an error with one line and exit 2, never an uncaught
// std::filesystem_error (exit 134).
TEST(RawlogBadInput, ExportOutputFolderErrorsAreOneLineAndExit2) {
  TempDir dir;
  recordedBytes(dir);
  const std::string rawlog = dir.file("base.rawlog");
  std::ofstream(dir.file("existing.txt")) << "not a folder\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--csv " + dir.file("existing.txt"), "exists and is not a directory"},
      {"--csv /proc/mft-no-such-dir", "cannot create the folder /proc/mft-no-such-dir"},
      {"--plot " + dir.file("existing.txt"), "exists and is not a directory"},
      {"--csv " + dir.file("existing.txt") + "/sub", "cannot create the folder"},
  };
  for (const auto& [args, expect] : cases) {
    const ToolRun r = runTool("mft-export", rawlog + " " + args, dir);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << args << ": " << r.err;
    EXPECT_LE(lineCount(r.err), 2u) << args << ": " << r.err;  // the error and CommandLine's "(see --help)" hint
  }
  EXPECT_EQ(fs::file_size(dir.file("existing.txt")), 13u) << "the existing file was touched";
}

// The channel order on disk, written out by hand here (not from the label tables in rawlog_format.cpp), so that
// a reordered table entry fails: every channel of these labels holds a distinct value.
namespace {
std::vector<double> channelsOf(const Message& m, const std::string& label) {
  ObservationEncoder enc;
  enc.encode(m, 1'700'000'000'000'000'000LL);
  std::vector<double> v;
  EXPECT_TRUE(observationValues(enc.observation(labelIndex(label)), labelIndex(label), &v));
  return v;
}
}  // namespace

TEST(RawlogFormat, ChannelOrderOnDiskIsPinned) {
  msg::WbcDiagnostics d;
  d.tick(7);
  d.solve_time_us(1.5);
  d.tick_time_us(2.5);
  d.iterations(3);
  d.status(4);
  d.active_constraints(5);
  d.slack_norm(6.5);
  d.task_error({11, 12, 13, 14, 15, 16});
  d.lti({21, 22});
  d.raci({31, 32});
  d.safety_events(41);
  d.holding(true);
  d.damping(false);
  EXPECT_EQ(channelsOf(d, "wbc_diag"),
            (std::vector<double>{7, 1.5, 2.5, 3, 4, 5, 6.5, 11, 12, 13, 14, 15, 16, 21, 22, 31, 32, 41, 1, 0}));

  msg::SensorData s;
  s.tick(9);
  s.actuated_pos({1, 3, 5, 7});
  s.passive_pos({2, 4, 6, 8});
  s.gyro_pitch_rate(0.25);
  s.accel({0.5, 9.75});
  EXPECT_EQ(channelsOf(s, "joint_q"), (std::vector<double>{9, 1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(channelsOf(s, "imu"), (std::vector<double>{-0.25, 0.5, 9.75}));

  msg::Reference r;
  r.tick(3);
  r.step_index(4);
  r.phase(0.5);
  r.stance_leg(-1);
  r.foot_in_stance({true, false});
  r.base_z({1, 2, 3});
  r.base_pitch({4, 5, 6});
  r.foot_pos({7, 8, 9, 10});
  r.foot_vel({11, 12, 13, 14});
  r.foot_acc({15, 16, 17, 18});
  r.base_x({19, 20, 21});
  r.hold_base_x(true);
  EXPECT_EQ(channelsOf(r, "plan_ref"), (std::vector<double>{3, 4, 0.5, -1, 1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12,
                                                            13, 14, 15, 16, 17, 18, 19, 20, 21, 1}));

  msg::RobotState st;
  st.q()[0] = 0.5;
  st.q()[1] = 0.4;
  st.q()[2] = 0.2;
  st.qd()[0] = 0.1;
  st.qd()[1] = -0.1;
  st.qd()[2] = 0.3;
  const auto base = channelsOf(st, "base_est");
  ASSERT_EQ(base.size(), 8u);
  EXPECT_EQ(base[0], 0.5);
  EXPECT_EQ(base[1], 0.4);
  EXPECT_EQ(base[2], -0.2);
  EXPECT_EQ(base[3], 0.1);
  EXPECT_EQ(base[4], -0.1);
  EXPECT_EQ(base[5], -0.3);
  EXPECT_DOUBLE_EQ(base[6], std::cos(-0.1));
  EXPECT_DOUBLE_EQ(base[7], std::sin(-0.1));

  msg::Disturbance p;
  p.seq(12);
  p.impulse(5.5);
  p.trigger(1);
  p.time_s(4.25);
  p.leg(0);
  EXPECT_EQ(channelsOf(p, "disturbance"), (std::vector<double>{12, 5.5, 1, 4.25, 0}));
}

// Every label: the columns named in the metadata and CSV header are exactly the channels written and read.
TEST(RawlogFormat, EveryLabelReadsBackWhatItWrote) {
  std::mt19937_64 g(17);
  auto msgs = tickMessages(5, g);
  msg::OperatorCommand o;
  o.seq(3), o.z_cmd(0.43), o.v_cmd(0.1), o.mode(2);
  msg::Disturbance d;
  d.seq(4), d.impulse(5.0), d.trigger(1), d.time_s(2.5), d.leg(1);
  msg::ConfigChange c;
  c.seq(5), c.applied(true), c.target(msg::CONFIG_TARGET_WBC), c.at_s(2.0), c.tick(2000), c.count(1);
  c.number({100.0, 0.0});
  std::snprintf(c.key().data(), c.key().size(), "%s", "gains.base_z.kp");
  msgs.insert(msgs.end(), {o, d, c});
  for (const auto& m : msgs) {
    ObservationEncoder enc;
    MessageAssembler asmb(0);
    Message back;
    std::int64_t t = 0;
    bool complete = false;
    for (int li : enc.encode(m, 1'000'000)) {
      std::vector<double> v;
      ASSERT_TRUE(observationValues(enc.observation(li), li, &v));
      EXPECT_EQ(v.size(), labels()[static_cast<std::size_t>(li)].columns.size()) << labels()[static_cast<std::size_t>(li)].label;
      complete = asmb.add(enc.observation(li), &back, &t);
    }
    ASSERT_TRUE(complete) << topicName(topicOf(m));
    ObservationEncoder again;
    for (int li : again.encode(back, t)) {
      std::vector<double> a, b;
      observationValues(enc.observation(li), li, &a);
      observationValues(again.observation(li), li, &b);
      EXPECT_EQ(a, b) << labels()[static_cast<std::size_t>(li)].label;
    }
  }
}

// Found by fuzzing (dds_sample, rawlog): a file's value out of an integer member's range, or a timestamp far from
// 1970, made the decoding's casts and arithmetic undefined. They saturate now.
TEST(RawlogBadInput, OutOfRangeTimestampsSaturate) {
  using Ticks = mrpt::Clock::duration;
  EXPECT_EQ(fromMrptTime(mrpt::Clock::time_point(Ticks(std::numeric_limits<Ticks::rep>::max()))),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(fromMrptTime(mrpt::Clock::time_point(Ticks(std::numeric_limits<Ticks::rep>::min()))),
            std::numeric_limits<std::int64_t>::min());
}

TEST(RawlogBadInput, OutOfRangeValuesOfIntegerFieldsSaturate) {
  msg::Disturbance d;
  d.seq(4), d.impulse(5.0), d.trigger(1), d.time_s(2.5), d.leg(1);
  ObservationEncoder enc;
  const int field = rawlog::layout::fieldIndex(Topic::Disturbance, "leg");
  ASSERT_GE(field, 0);
  for (int li : enc.encode(Message(d), 1'000'000)) {
    const auto& l = rawlog::layout::table()[static_cast<std::size_t>(li)];  // the encoder's observations follow it
    for (std::size_t c = 0; c < l.channels.size(); ++c) {
      if (l.cls != LabelClass::RawDaq || l.channels[c].field != field) continue;
      auto o = dynamic_cast<const mrpt::obs::CObservationRawDAQ&>(enc.observation(li));
      o.AIN_32bits.clear();  // a file without exact copies: the doubles are read
      using Leg = std::decay_t<decltype(d.leg())>;
      for (const auto& [value, expected] : {std::pair{1e30, std::numeric_limits<Leg>::max()},
                                            std::pair{-1e30, std::numeric_limits<Leg>::lowest()},
                                            std::pair{std::nan(""), static_cast<Leg>(0)}}) {
        o.AIN_double[c] = value;
        Message back{msg::Disturbance{}};
        ASSERT_TRUE(rawlog::layout::read(l, o, &back)) << l.label;
        EXPECT_EQ(std::get<msg::Disturbance>(back).leg(), expected) << value;
      }
      return;
    }
  }
  FAIL() << "no RawDAQ channel holds Disturbance.leg";
}
