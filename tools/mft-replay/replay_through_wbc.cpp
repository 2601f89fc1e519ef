// mft-replay --through-wbc, in named steps: rebuild the controller from the recording, pair each tick's inputs
// with the recorded answer, run the ticks in order, report.
#include "tools/mft-replay/replay_through_wbc.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "common/json_writer.hpp"
#include "model/mft_polytope.hpp"
#include "services/runtime/convert.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/whole_body_controller.hpp"

namespace mft::replay {

namespace {

// The WBC changes applied while the run was recorded (live tuning, docs/guide/live-tuning.md): a first pass over the
// file collects the applied ConfigChange records of mft-wbc (written some ticks after the tick they act from), and
// each becomes the controller's weights and gains from its tick on, judged by the same strict loader as live.
struct RecordedChange {
  std::uint64_t seq = 0, tick = 0;
  std::string key, value;
  wbc::WbcTuning tuning;
};

RecordedChange recordedChangeOf(const msg::ConfigChange& c) {
  RecordedChange r;
  r.seq = c.seq();
  r.tick = c.tick();
  r.key.assign(c.key().data(), strnlen(c.key().data(), c.key().size()));
  r.value.assign(c.value().data(), strnlen(c.value().data(), c.value().size()));
  if (r.key.empty() || r.value.empty())
    throw std::runtime_error("a recorded live change (seq " + std::to_string(r.seq) + ") names no tunable key or value");
  return r;
}

std::vector<RecordedChange> recordedWbcChanges(const std::string& path, const std::string& base_text,
                                               const model::RobotDescription& robot) {
  rawlog::RawlogReader reader(path);
  rawlog::MessageAssembler assembler(reader.metadata().time_base_unix_ns);
  mrpt::obs::CObservation::Ptr obs;
  rawlog::Message m;
  std::int64_t unix_ns = 0;
  std::vector<RecordedChange> out;
  while (reader.next(&obs)) {
    if (!assembler.add(*obs, &m, &unix_ns) || !std::holds_alternative<msg::ConfigChange>(m)) continue;
    const auto& c = std::get<msg::ConfigChange>(m);
    if (c.applied() && c.target() == msg::CONFIG_TARGET_WBC) out.push_back(recordedChangeOf(c));
  }
  // In the order they took effect (seq breaks a tie: the order mft-wbc applied them in).
  std::stable_sort(out.begin(), out.end(), [](const RecordedChange& a, const RecordedChange& b) {
    return a.tick != b.tick ? a.tick < b.tick : a.seq < b.seq;
  });
  std::string text = base_text;
  for (auto& r : out) {
    auto o = wbc::applyWbcOverride(text, "recorded wbc.yaml (live change)", r.key, r.value, robot);
    r.tuning = wbc::tuningOf(o.config);
    text = o.yaml_text;
  }
  return out;
}

// The controller of the recording, with the live changes to apply along the way.
struct Rebuilt {
  model::RobotDescription robot;
  model::MftPolytope polytope;
  std::unique_ptr<wbc::WholeBodyController> controller;
  std::vector<RecordedChange> changes;
};

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Throws with the reason when the recording cannot give the controller back.
void rebuild(const rawlog::RawlogReader& reader, const config::CommandLine& cli, Rebuilt* out) {
  const auto& md = reader.metadata();
  auto need = [&](const std::string& name) -> const std::string& {
    auto it = md.config.find(name);
    if (it == md.config.end()) throw std::runtime_error("the recording has no " + name + " in its metadata");
    return it->second;
  };
  out->robot = model::parseRobotDescription(need("robot.yaml"), "recorded robot.yaml");
  if (!md.robot_checksum.empty() && model::checksumHex(out->robot.checksum) != md.robot_checksum)
    throw std::runtime_error("the recorded robot.yaml does not match the recorded checksum " + md.robot_checksum);
  wbc::WbcConfig config = cli.isSet("wbc-config") ? wbc::loadWbcConfig(cli.get("wbc-config"))
                                                  : wbc::parseWbcConfig(need("wbc.yaml"), "recorded wbc.yaml");
  out->polytope = model::parseMftPolytope(need("mft_space.yaml"), "recorded mft_space.yaml", out->robot);
  // As mft-wbc does: the scenario chooses the variant.
  if (!wbc::parseVariant(md.controller, &config.variant))
    throw std::runtime_error("unknown recorded controller '" + md.controller + "'");
  out->controller = std::make_unique<wbc::WholeBodyController>(out->robot, config, &out->polytope);
  if (cli.isSet("ignore-live-changes")) return;
  const std::string base_text = cli.isSet("wbc-config") ? fileText(cli.get("wbc-config")) : need("wbc.yaml");
  out->changes = recordedWbcChanges(reader.path(), base_text, out->robot);
}

// mft-wbc answers tick k from RobotState(k) and Reference(k) (lockstep). The recorder stores samples in the
// order they reached it, which on a loaded machine is not always the order they were sent (JointCommand(k)
// can come before the Reference(k) it answers): inputs and answers are paired by tick, and the controller,
// which carries state from tick to tick (the force-rate term, its warm start), runs the ticks in order.
class TickComparer {
 public:
  TickComparer(Rebuilt& rebuilt, double tolerance) : r_(rebuilt), tolerance_(tolerance) {}

  // Takes one recorded message; runs every tick it completes.
  void add(const rawlog::Message& m) {
    std::uint64_t tick = 0;
    if (const auto* s = std::get_if<msg::RobotState>(&m)) {
      model::RobotStateEstimate state;
      services::fromMsg(*s, &state);
      tick = state.tick;
      pending_[tick].state = state;
    } else if (const auto* f = std::get_if<msg::Reference>(&m)) {
      wbc::WbcReference ref;
      services::fromMsg(*f, &ref);
      tick = ref.tick;
      pending_[tick].ref = ref;
    } else if (const auto* c = std::get_if<msg::JointCommand>(&m)) {
      tick = c->tick();
      pending_[tick].command = *c;
    } else {
      return;
    }
    newest_ = std::max(newest_, tick);
    drain(false);
  }
  void finish() { drain(true); }

  std::uint64_t compared = 0, unmatched = 0, mode_mismatches = 0, differing = 0;
  long long first_diff_tick = -1, max_diff_tick = -1;
  double max_diff = 0.0, first_diff_value = 0.0;
  std::size_t next_change = 0;

 private:
  struct Tick {
    std::optional<model::RobotStateEstimate> state;
    std::optional<wbc::WbcReference> ref;
    std::optional<msg::JointCommand> command;
  };
  // A tick still incomplete this many ticks behind the newest one never will be (the recorder reorders only
  // within a few samples).
  static constexpr std::uint64_t kReorderWindow = 256;

  void compare(const model::RobotStateEstimate& state, const wbc::WbcReference& ref, const msg::JointCommand& rec) {
    // The recorded live changes due at this tick, at the tick boundary as in mft-wbc.
    for (; next_change < r_.changes.size() && r_.changes[next_change].tick <= rec.tick(); ++next_change)
      r_.controller->setTuning(r_.changes[next_change].tuning);
    wbc::WbcDiagnostics diag;
    const model::ActuatorCommand cmd = r_.controller->update(state, ref, &diag);
    double d = 0.0;
    for (int i = 0; i < 4; ++i) d = std::max(d, std::abs(cmd.tau[i] - rec.tau()[static_cast<std::size_t>(i)]));
    if (!(d == d)) d = std::numeric_limits<double>::infinity();
    const bool mode_differs = (cmd.mode == model::CommandMode::Damping) != (rec.mode() == msg::COMMAND_MODE_DAMPING);
    if (mode_differs) ++mode_mismatches;
    if (d > max_diff) {
      max_diff = d;
      max_diff_tick = static_cast<long long>(rec.tick());
    }
    if (d > tolerance_ || mode_differs) {
      ++differing;
      if (first_diff_tick < 0) {
        first_diff_tick = static_cast<long long>(rec.tick());
        first_diff_value = d;
      }
    }
    ++compared;
  }
  // Runs every complete tick at the front; drops a front tick that can no longer complete (all: at the end of
  // the file). A dropped tick with a command counts as unmatched.
  void drain(bool all) {
    while (!pending_.empty()) {
      auto& [tick, t] = *pending_.begin();
      if (t.state && t.ref && t.command) {
        compare(*t.state, *t.ref, *t.command);
      } else if (all || newest_ > tick + kReorderWindow) {
        if (t.command) ++unmatched;
      } else {
        break;
      }
      pending_.erase(pending_.begin());
    }
  }

  Rebuilt& r_;
  double tolerance_;
  std::map<std::uint64_t, Tick> pending_;
  std::uint64_t newest_ = 0;
};

void printReport(const rawlog::RawlogReader& reader, const TickComparer& c, const Rebuilt& r, double tolerance,
                 bool json) {
  const auto& md = reader.metadata();
  const bool ok = c.compared > 0 && c.differing == 0;
  if (json) {
    config::JsonWriter w;
    w.beginObject().field("mode", "through-wbc").field("file", reader.path()).field("ticks_compared", c.compared);
    w.field("unmatched_commands", c.unmatched).field("max_abs_diff_Nm", c.max_diff, 17).field("max_diff_tick", c.max_diff_tick);
    w.field("tolerance", tolerance, 17).field("differing_ticks", c.differing).field("first_differing_tick", c.first_diff_tick);
    w.field("first_difference_Nm", c.first_diff_value, 17).field("mode_mismatches", c.mode_mismatches);
    w.field("live_changes", r.changes.size()).field("live_changes_applied", c.next_change);
    w.field("end", rawlog::toString(reader.end())).field("end_message", reader.endMessage()).field("ok", ok);
    std::printf("%s\n", w.endObject().str().c_str());
    return;
  }
  std::printf("through-wbc  %s (%s, controller %s)\n", reader.path().c_str(), md.mode.c_str(), md.controller.c_str());
  std::printf("compared     %llu ticks (%llu commands without their state/reference)\n",
              static_cast<unsigned long long>(c.compared), static_cast<unsigned long long>(c.unmatched));
  std::printf("max |dtau|   %.3g N m (tick %lld), tolerance %.3g N m\n", c.max_diff, c.max_diff_tick, tolerance);
  for (const auto& ch : r.changes)
    std::printf("live change  wbc.%s = %s from tick %llu\n", ch.key.c_str(), ch.value.c_str(),
                static_cast<unsigned long long>(ch.tick));
  if (c.differing) std::printf("DIFFERENT    %llu ticks, first at tick %lld (%.3g N m)\n",
                               static_cast<unsigned long long>(c.differing), c.first_diff_tick, c.first_diff_value);
  else std::printf("identical    within the tolerance\n");
  std::printf("file         %s\n", reader.endMessage().c_str());
}

}  // namespace

int throughWbc(rawlog::RawlogReader& reader, const config::CommandLine& cli) {
  const auto& md = reader.metadata();
  const double tolerance = cli.getDouble("tolerance", 0.0, 1e9);
  Rebuilt rebuilt;
  try {
    rebuild(reader, cli, &rebuilt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mft-replay: cannot rebuild the controller from the recording: %s\n", e.what());
    return kExitBadInput;
  }
  if (md.mode != "lockstep")
    std::fprintf(stderr, "mft-replay: warning: a %s recording: the live controller may have paired states and "
                         "references differently, so differences are expected\n", md.mode.c_str());
  TickComparer comparer(rebuilt, tolerance);
  rawlog::MessageAssembler assembler(md.time_base_unix_ns);
  mrpt::obs::CObservation::Ptr obs;
  rawlog::Message m;
  std::int64_t unix_ns = 0;
  while (reader.next(&obs))
    if (assembler.add(*obs, &m, &unix_ns)) comparer.add(m);
  comparer.finish();
  printReport(reader, comparer, rebuilt, tolerance, cli.isSet("json"));
  if (reader.end() == rawlog::RawlogReader::End::Truncated)
    std::fprintf(stderr, "mft-replay: the file is truncated: compared up to its last whole record\n");
  if (reader.end() == rawlog::RawlogReader::End::Corrupt) {
    std::fprintf(stderr, "mft-replay: the file is %s\n", reader.endMessage().c_str());
    return kExitCorrupt;
  }
  if (comparer.compared == 0) std::fprintf(stderr, "mft-replay: no JointCommand could be compared\n");
  return comparer.compared > 0 && comparer.differing == 0 ? 0 : kExitMismatch;
}

}  // namespace mft::replay
