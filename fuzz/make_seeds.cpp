// Writes the seed inputs of the fuzz targets that are binary (fuzz/corpus/dds_sample, fuzz/corpus/rawlog): one
// valid sample of every topic serialized as the stack's writers serialize it, a few refused ones, and short
// recordings as mft-record writes them (gzip, stored, plain, cut). Run once by hand: fuzz_make_seeds CORPUS_DIR.
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>

#include "idl/msg_pubsub.hpp"
#include "services/record/recorder.hpp"

namespace {

using namespace mft;

template <class M>
void writeSample(const std::string& dir, const std::string& name, const M& m) {
  typename msg::PubSubOf<M>::type type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.m_typeSize);
  type.serialize(const_cast<M*>(&m), &payload);
  std::ofstream out(dir + "/" + name, std::ios::binary);
  const char topic = static_cast<char>(msg::TopicOf<M>::index);
  out.write(&topic, 1);
  out.write(reinterpret_cast<const char*>(payload.data), payload.length);
}

void ddsSeeds(const std::string& dir) {
  std::filesystem::create_directories(dir);
  msg::forEachTopicType([&](auto tag) {
    using M = typename decltype(tag)::type;
    M m{};
    if constexpr (std::is_same_v<M, msg::OperatorCommand>) m.z_cmd(0.42);
    if constexpr (std::is_same_v<M, msg::ConfigChange>) {
      std::snprintf(m.key().data(), m.key().size(), "weights.slack");
      std::snprintf(m.value().data(), m.value().size(), "1e3");
    }
    writeSample(dir, "accept-" + std::string(msg::topicInfo<M>().type), m);
  });
  msg::JointCommand jc;
  jc.tau()[1] = std::nan("");
  writeSample(dir, "refuse-JointCommand-nan", jc);
  msg::OperatorCommand oc;
  oc.z_cmd(0.42), oc.mode(7);
  writeSample(dir, "refuse-OperatorCommand-mode", oc);
  msg::ConfigChange cc;
  std::snprintf(cc.key().data(), cc.key().size(), "variant");
  std::snprintf(cc.value().data(), cc.value().size(), "sa");
  writeSample(dir, "refuse-ConfigChange-structure", cc);
}

// Two ticks of every tick topic and one event of each kind, recorded at `level` (0: stored blocks).
void record(const std::string& path, int level) {
  rawlog::RecorderOptions opt;
  opt.output = path;
  opt.gzip_level = level;
  opt.metadata.mode = "lockstep";
  opt.metadata.scenario_name = "seed";
  opt.metadata.controller = "mft";
  opt.metadata.config["robot.yaml"] = "schema_version: 1\n";
  rawlog::Recorder rec(opt);
  rec.start();
  for (std::uint64_t k = 0; k < 2; ++k) {
    msg::GroundTruth gt; gt.tick(k), gt.stamp_ns(k * 1000000);
    msg::SensorData sd; sd.tick(k), sd.stamp_ns(k * 1000000);
    msg::RobotState rs; rs.tick(k), rs.stamp_ns(k * 1000000);
    msg::Reference rf; rf.tick(k), rf.stamp_ns(k * 1000000);
    msg::JointCommand jc; jc.tick(k), jc.stamp_ns(k * 1000000);
    msg::WbcDiagnostics wd; wd.tick(k), wd.stamp_ns(k * 1000000);
    for (const rawlog::Message& m : {rawlog::Message(gt), rawlog::Message(sd), rawlog::Message(rs), rawlog::Message(rf),
                                     rawlog::Message(jc), rawlog::Message(wd)})
      rec.push(m);
  }
  msg::ConfigChange cc;
  std::snprintf(cc.key().data(), cc.key().size(), "weights.slack");
  std::snprintf(cc.value().data(), cc.value().size(), "1e3");
  for (const rawlog::Message& m : {rawlog::Message(msg::OperatorCommand{}), rawlog::Message(msg::Disturbance{}),
                                   rawlog::Message(cc), rawlog::Message(msg::CommandVerdict{})})
    rec.push(m);
  rec.stop();
  std::filesystem::remove(rawlog::sidecarName(path));
}

void rawlogSeeds(const std::string& dir) {
  std::filesystem::create_directories(dir);
  record(dir + "/accept-two-ticks.rawlog", 1);
  record(dir + "/accept-two-ticks-stored.rawlog", 0);
  gzFile in = gzopen((dir + "/accept-two-ticks.rawlog").c_str(), "rb");
  std::string plain(1 << 20, '\0');
  plain.resize(static_cast<std::size_t>(gzread(in, plain.data(), static_cast<unsigned>(plain.size()))));
  gzclose(in);
  std::ofstream(dir + "/accept-two-ticks-plain.rawlog", std::ios::binary) << plain;
  std::ofstream(dir + "/accept-two-ticks-cut.rawlog", std::ios::binary) << plain.substr(0, plain.size() * 3 / 4);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds CORPUS_DIR (writes CORPUS_DIR/dds_sample and CORPUS_DIR/rawlog)\n");
    return 2;
  }
  ddsSeeds(std::string(argv[1]) + "/dds_sample");
  rawlogSeeds(std::string(argv[1]) + "/rawlog");
  return 0;
}
