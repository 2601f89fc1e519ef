#include "tools/mft-export/video.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/tool_io.hpp"
#include "model/mft_polytope.hpp"
#include "model/robot_description.hpp"
#include "services/record/rawlog_reader.hpp"
#include "chain/input_guard.hpp"
#include "chain/scenario.hpp"
#include "sim/terrain.hpp"
#include "tools/mft-export/robot_drawing.hpp"

namespace mft::video {
namespace {

namespace fs = std::filesystem;

constexpr int kExitBadInput = 2;
constexpr int kExitCorrupt = 4;
constexpr int kExitInterrupted = 130;
// mft-sim refuses a Disturbance beyond --max-push (default 200 N s); such a request is not drawn as a push.
constexpr double kSimMaxPushNs = 200.0;

constexpr int kPosition = 9;  // significant digits of positions in the renderer's JSON
void writePoint(config::JsonWriter& w, const char* key, const Eigen::Vector2d& p) {
  w.key(key).numbers({p.x(), p.y()}, kPosition);
}

std::string controllerTitle(const std::string& c) {
  if (c == "mft") return "MFT-WBC";
  if (c == "sa") return "SA-WBC";
  if (c == "none") return "WBC without MFT or SA terms";
  return c.empty() ? "unknown controller" : c;
}

// A push as the simulator applies it: at a time, or at the first lift-off of a leg after it was armed.
struct PushEvent {
  double impulse_Ns = 0.0;
  int leg = -1;           // -1: at armed_s itself; 0 right, 1 left: at that foot's next lift-off
  double armed_s = 0.0;
  bool applied = false;
  double applied_s = 0.0;
};

// One recording and the state of its stream at the newest video frame.
class Panel {
 public:
  explicit Panel(std::string path) : path_(std::move(path)) {}

  // Reads the metadata and rebuilds what the drawing needs; false with *error set when it cannot.
  bool open(std::string* error, std::vector<std::string>* warnings) {
    try {
      reader_ = std::make_unique<rawlog::RawlogReader>(path_);
    } catch (const rawlog::NotMftRawlog& e) {
      *error = std::string("refused: ") + e.what();
      return false;
    }
    const auto& md = reader_->metadata();
    assembler_ = std::make_unique<rawlog::MessageAssembler>(md.time_base_unix_ns);
    auto text = [&](const std::string& name) -> const std::string* {
      auto it = md.config.find(name);
      return it == md.config.end() ? nullptr : &it->second;
    };
    const std::string* robot_text = text("robot.yaml");
    if (!robot_text) {
      *error = path_ + ": the recording has no robot.yaml in its metadata (needed to draw the robot)";
      return false;
    }
    try {
      robot_ = model::parseRobotDescription(*robot_text, "recorded robot.yaml");
    } catch (const std::exception& e) {
      *error = path_ + ": " + config::oneLine(e.what());
      return false;
    }
    drawer_ = std::make_unique<RobotDrawer>(robot_);
    if (const std::string* mft = text("mft_space.yaml")) {
      try {
        polytope_ = model::parseMftPolytope(*mft, "recorded mft_space.yaml", robot_);
      } catch (const std::exception& e) {
        warnings->push_back(path_ + ": legs not coloured by the MFT space: " + config::oneLine(e.what()));
      }
    } else {
      warnings->push_back(path_ + ": no mft_space.yaml in the metadata: legs not coloured by the MFT space");
    }
    terrain_ = sim::Terrain::flat();
    if (const std::string* scen = text("scenario")) {
      try {
        scenario_ = chain::parseScenario(*scen, "recorded scenario");
        for (const auto& p : scenario_->pushes) pushes_.push_back({p.impulse_Ns, p.at_liftoff_leg, p.at_s});
        const std::string terrain_key = "terrain/" + scenario_->terrain + ".yaml";
        if (const std::string* t = text(terrain_key)) terrain_ = sim::parseTerrain(*t, "recorded " + terrain_key);
        else warnings->push_back(path_ + ": no " + terrain_key + " in the metadata: ground drawn flat at z = 0");
      } catch (const std::exception& e) {
        warnings->push_back(path_ + ": recorded scenario not usable (" + config::oneLine(e.what()) +
                            "): no pushes drawn, ground drawn flat");
        scenario_.reset();
        pushes_.clear();
        terrain_ = sim::Terrain::flat();
      }
    } else {
      warnings->push_back(path_ + ": no scenario in the metadata: no pushes drawn, ground drawn flat");
    }
    return true;
  }

  const std::string& path() const { return path_; }
  const rawlog::RawlogReader& reader() const { return *reader_; }
  const rawlog::Metadata& metadata() const { return reader_->metadata(); }
  // The scenario's length: what the progress bar expects (a run that fell ends earlier); 0 if unknown.
  double expectedDuration() const { return scenario_ ? scenario_->duration_s : 0.0; }
  bool hasSample() const { return have_gt_; }
  bool atEnd() const { return at_end_; }
  double sampleTime() const { return gt_t_; }

  // Reads on until the first ground-truth sample at or after simulated time t (or the end of the file).
  void advanceTo(double t) {
    mrpt::obs::CObservation::Ptr obs;
    rawlog::Message m;
    std::int64_t unix_ns = 0;
    while (!at_end_ && (!have_gt_ || gt_t_ < t - 1e-9)) {
      if (!reader_->next(&obs)) {
        at_end_ = true;
        break;
      }
      if (!assembler_->add(*obs, &m, &unix_ns)) continue;
      switch (rawlog::topicOf(m)) {
        case rawlog::Topic::GroundTruth:
          gt_ = std::get<msg::GroundTruth>(m);
          gt_t_ = static_cast<double>(gt_.stamp_ns()) * 1e-9;
          have_gt_ = true;
          for (auto& p : pushes_)
            if (!p.applied && p.leg < 0 && gt_t_ >= p.armed_s - 1e-9) {
              p.applied = true;
              p.applied_s = p.armed_s;
            }
          break;
        case rawlog::Topic::SensorData: {
          // The simulator applies an armed lift-off push in the physics step after the foot's contact ends;
          // the foot switch is that contact state, so its 1 -> 0 edge is the push's tick (within 1 ms).
          const auto& s = std::get<msg::SensorData>(m);
          const double ts = static_cast<double>(s.stamp_ns()) * 1e-9;
          for (int leg = 0; leg < 2; ++leg) {
            const bool now = s.contact()[static_cast<std::size_t>(leg)];
            if (have_contact_ && contact_[static_cast<std::size_t>(leg)] && !now)
              for (auto& p : pushes_)
                if (!p.applied && p.leg == leg && ts >= p.armed_s) {
                  p.applied = true;
                  p.applied_s = ts;
                }
            contact_[static_cast<std::size_t>(leg)] = now;
          }
          have_contact_ = true;
          break;
        }
        case rawlog::Topic::Disturbance: {
          // A push sent on the topic (mft-cmd --push): armed when it arrived (its stamp is the newest
          // simulated time the recorder had seen), applied as the simulator does.
          const auto& d = std::get<msg::Disturbance>(m);
          if (chain::checkDisturbance(d.impulse(), d.trigger(), d.time_s(), d.leg(), kSimMaxPushNs) !=
              chain::InputVerdict::Ok)
            break;
          const double arrived = static_cast<double>(unix_ns - metadata().time_base_unix_ns) * 1e-9;
          if (d.trigger() == msg::TRIGGER_AT_TIME) pushes_.push_back({d.impulse(), -1, std::max(arrived, d.time_s())});
          else pushes_.push_back({d.impulse(), d.leg(), arrived});
          break;
        }
        default:
          break;
      }
    }
  }

  // Everything the renderer needs once: names, the robot's size, the ground profile.
  std::string headerJson() const {
    const auto& md = metadata();
    config::JsonWriter w;
    w.beginObject().field("file", path_).field("scenario", md.scenario_name).field("controller", md.controller);
    w.field("title", controllerTitle(md.controller)).field("mode", md.mode).field("mft_space", polytope_.has_value());
    w.fixedField("duration_s", expectedDuration(), 6).fixedField("leg_reach_m", robot_.thigh.length_m + robot_.shank.length_m, 6);
    w.key("terrain").beginObject().field("name", scenario_ ? scenario_->terrain : std::string("flat"));
    // Breakpoints of the piecewise-linear profile, just either side of every segment end, so a step (a board
    // edge) is a vertical line and the flat ground before the first segment keeps its own height.
    std::vector<double> xs;
    constexpr double kEps = 1e-7;
    for (const auto& seg : terrain_.segments) {
      xs.insert(xs.end(), {seg.x0 - kEps, seg.x0 + kEps, seg.x1() - kEps, seg.x1() + kEps});
      for (std::size_t i = 1; i + 1 < seg.samples.size(); ++i) xs.push_back(seg.x0 + static_cast<double>(i) * seg.spacing);
    }
    if (xs.empty()) xs.push_back(terrain_.start_x);
    std::sort(xs.begin(), xs.end());
    w.key("x").beginArray();
    for (const double x : xs) w.value(x, kPosition);
    w.endArray().key("z").beginArray();
    for (const double x : xs) w.value(terrain_.heightAt(x), kPosition);
    return w.endArray().endObject().endObject().str();
  }

  // The current frame of this panel (the newest sample at or after the frame time, or the last one).
  std::string frameJson(double t) const {
    model::VectorQ q;
    for (int i = 0; i < model::kNq; ++i) q[i] = gt_.q()[static_cast<std::size_t>(i)];
    const RobotDrawing d = drawer_->draw(q);
    config::JsonWriter w;
    w.beginObject().fixedField("t", gt_t_, 6).field("tick", gt_.tick()).field("ended", at_end_ && gt_t_ < t - 1e-9);
    w.key("base").numbers({d.base.x(), d.base.y(), d.base.z()}, kPosition);
    w.field("ground_z", terrain_.heightAt(d.base.x()), kPosition).key("torso").beginArray();
    for (const auto& p : d.torso) w.numbers({p.x(), p.y()}, kPosition);
    w.endArray();
    writePoint(w, "com", d.torso_com);
    w.key("legs").beginArray();
    for (int leg = 0; leg < model::kNumLegs; ++leg) {
      const auto& l = d.legs[static_cast<std::size_t>(leg)];
      w.beginObject();
      writePoint(w, "hip_rear", l.hip_rear);
      writePoint(w, "hip_fore", l.hip_fore);
      writePoint(w, "knee_rear", l.knee_rear);
      writePoint(w, "knee_fore", l.knee_fore);
      writePoint(w, "foot", l.foot);
      writePoint(w, "foot_fore", l.foot_fore);
      const double q_rear = q[model::hipRearIndex(leg)], q_fore = q[model::hipForeIndex(leg)];
      const auto li = static_cast<std::size_t>(leg);
      w.field("closed", l.closed_by_kinematics).key("inside_mft");
      if (polytope_) w.value(polytope_->leg.contains(q_rear, q_fore));
      else w.null();
      w.field("lti", gt_.lti()[li], 6).key("force");
      w.numbers({gt_.contact_force()[2 * li], gt_.contact_force()[2 * li + 1]}, 6).endObject();
    }
    w.endArray().key("push");
    const PushEvent* latest = nullptr;
    for (const auto& p : pushes_)
      if (p.applied && p.applied_s <= gt_t_ + 1e-9 && (!latest || p.applied_s >= latest->applied_s)) latest = &p;
    if (latest) w.beginObject().field("impulse_Ns", latest->impulse_Ns, 6).fixedField("t", latest->applied_s, 6).endObject();
    else w.null();
    return w.endObject().str();
  }

 private:
  std::string path_;
  std::unique_ptr<rawlog::RawlogReader> reader_;
  std::unique_ptr<rawlog::MessageAssembler> assembler_;
  model::RobotDescription robot_;
  std::unique_ptr<RobotDrawer> drawer_;
  std::optional<model::MftPolytope> polytope_;
  std::optional<chain::Scenario> scenario_;
  sim::Terrain terrain_;
  std::vector<PushEvent> pushes_;
  msg::GroundTruth gt_;
  double gt_t_ = -1.0;
  bool have_gt_ = false, at_end_ = false;
  std::array<bool, 2> contact_{};
  bool have_contact_ = false;
};

// Why the MP4 at `path` is not whole, or "": its top-level boxes must tile the file and hold the index (moov),
// which ffmpeg writes last. On a full disk ffmpeg exited 0 and left a file without it, which no player opens.
std::string incompleteMp4(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(std::max<std::streamoff>(0, in.tellg()));
  in.seekg(0);
  bool has_moov = false;
  for (std::uint64_t at = 0; at < size;) {
    unsigned char box[16] = {};
    if (size - at < 8 || !in.read(reinterpret_cast<char*>(box), 8)) return "cut inside a box header";
    std::uint64_t len = (std::uint64_t{box[0]} << 24) | (box[1] << 16) | (box[2] << 8) | box[3];
    if (len == 1) {
      if (size - at < 16 || !in.read(reinterpret_cast<char*>(box + 8), 8)) return "cut inside a box header";
      len = 0;
      for (int i = 8; i < 16; ++i) len = (len << 8) | box[i];
    } else if (len == 0) {
      len = size - at;  // to the end of the file
    }
    if (len < 8 || len > size - at) return "a box runs past the end of the file";
    has_moov = has_moov || std::string(reinterpret_cast<char*>(box + 4), 4) == "moov";
    at += len;
    in.seekg(static_cast<std::streamoff>(at));
  }
  return has_moov ? "" : "no index (moov box)";
}

std::string lowerExtension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// The first executable `name` on PATH ("" if none).
std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

std::string seconds(double s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f s", s);
  return buf;
}

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// What --video asks for, checked before anything is read.
struct VideoRequest {
  std::string out, ext, ffmpeg;
  double speed = 1.0, from = 0.0, to = INFINITY;
  long fps = 30;
};

// The options of --video (a bad one is a usage error); 0, or the exit status when a tool is missing.
int videoRequest(const services::CommandLine& cli, VideoRequest* r) {
  r->out = cli.get("video");
  r->ext = lowerExtension(r->out);
  if (r->ext != ".mp4" && r->ext != ".gif") cli.fail("--video: " + r->out + " must end in .mp4 or .gif");
  for (const char* other : {"csv", "plot", "info", "labels"})
    if (cli.isSet(other)) cli.fail(std::string("--video cannot be combined with --") + other);
  r->speed = cli.isSet("speed") ? cli.getDouble("speed", 0.01, 1000.0) : 1.0;
  r->fps = cli.isSet("fps") ? cli.getInt("fps", 1, 120) : (r->ext == ".gif" ? 15 : 30);
  r->from = cli.isSet("from") ? cli.getDouble("from", 0.0, 1e7) : 0.0;
  r->to = cli.isSet("to") ? cli.getDouble("to", 0.0, 1e7) : INFINITY;
  if (!(r->to > r->from))
    cli.fail("--to must be after --from (got --from " + cli.get("from") + " --to " + cli.get("to") + ")");
  std::error_code ec;
  if (fs::is_directory(r->out, ec)) cli.fail("--video: " + r->out + " is a directory");
  if (fs::exists(r->out, ec) && !cli.isSet("overwrite"))
    cli.fail("--video: " + r->out + " already exists: refusing to replace it (--overwrite replaces it)");
  r->ffmpeg = findOnPath("ffmpeg");
  if (r->ffmpeg.empty()) {
    std::fprintf(stderr, "mft-export: --video needs ffmpeg, which is not on PATH (Debian: apt-get install ffmpeg)\n");
    return kExitBadInput;
  }
  if (::access("/usr/bin/python3", X_OK) != 0) {
    std::fprintf(stderr, "mft-export: --video needs /usr/bin/python3 with python3-matplotlib (Debian: apt-get install "
                         "python3-matplotlib)\n");
    return kExitBadInput;
  }
  return 0;
}

// The recording (and --beside's) opened; 0, or the exit status. Sets the longest expected duration.
int openPanels(const services::CommandLine& cli, const std::string& file, const VideoRequest& r,
               std::vector<std::unique_ptr<Panel>>* panels, double* expected_end) {
  std::vector<std::string> warnings;
  panels->push_back(std::make_unique<Panel>(file));
  if (cli.isSet("beside")) panels->push_back(std::make_unique<Panel>(cli.get("beside")));
  for (auto& p : *panels) {
    std::string error;
    if (!p->open(&error, &warnings)) {
      std::fprintf(stderr, "mft-export: %s\n", error.c_str());
      return kExitBadInput;
    }
  }
  *expected_end = 0.0;
  for (const auto& p : *panels) *expected_end = std::max(*expected_end, p->expectedDuration());
  if (*expected_end > 0.0 && r.from >= *expected_end)
    cli.fail("--from " + cli.get("from") + " s is not before the end of the run (" + seconds(*expected_end) + ")");
  for (const auto& w : warnings) std::fprintf(stderr, "mft-export: warning: %s\n", w.c_str());
  return 0;
}

// The renderer's first line: the output, the clock and the panels.
std::string headerLine(const services::CommandLine& cli, const VideoRequest& r, const std::string& tmp,
                       const std::vector<std::unique_ptr<Panel>>& panels, double expected_end) {
  const double frame_dt = r.speed / static_cast<double>(r.fps);
  const double end_for_estimate = std::min(r.to, expected_end);
  // A recording of D s holds samples up to D - 1 ms: frames at from + i dt for from + i dt < D.
  const long frames_expected =
      end_for_estimate > r.from ? static_cast<long>(std::ceil((end_for_estimate - r.from) / frame_dt - 1e-6)) : 0;
  config::JsonWriter header_json;
  header_json.beginObject().field("type", "header").field("output", tmp).field("final_output", r.out);
  header_json.field("format", r.ext.substr(1)).field("ffmpeg", r.ffmpeg).field("fps", r.fps).field("speed", r.speed, kPosition);
  header_json.field("from_s", r.from, kPosition).field("frames_expected", frames_expected);
  header_json.field("frame_log", cli.get("frame-log")).key("panels").beginArray();
  for (const auto& p : panels) header_json.raw(p->headerJson());
  return header_json.endArray().endObject().str() + "\n";
}

struct Rendered {
  long frames = 0;
  double last_t = 0.0, wall_s = 0.0;
  bool interrupted = false;
  int rc = 0;  // the renderer's exit status
};

// Frames at from + i dt while any recording still has data at that time (one that ended shows its last state),
// one JSON line each into the renderer.
Rendered renderFrames(const std::string& header, const VideoRequest& r, std::vector<std::unique_ptr<Panel>>& panels,
                      std::FILE* renderer) {
  const double frame_dt = r.speed / static_cast<double>(r.fps);
  const auto t0 = std::chrono::steady_clock::now();
  Rendered out;
  out.last_t = r.from;
  bool write_failed = std::fputs(header.c_str(), renderer) < 0;
  while (!write_failed) {
    if (services::shutdownRequested()) {
      out.interrupted = true;
      break;
    }
    const double t = r.from + static_cast<double>(out.frames) * frame_dt;
    if (t >= r.to - 1e-9) break;  // frames cover [from, to): the video lasts (to - from) / speed
    bool any_running = false;
    for (auto& p : panels) {
      p->advanceTo(t);
      any_running = any_running || (p->hasSample() && p->sampleTime() >= t - 1e-9);
    }
    if (!any_running) break;
    config::JsonWriter frame;
    frame.beginObject().field("type", "frame").field("i", out.frames).key("panels").beginArray();
    for (const auto& p : panels) frame.raw(p->frameJson(t));
    const std::string line = frame.endArray().endObject().str() + "\n";
    write_failed = std::fputs(line.c_str(), renderer) < 0;
    out.last_t = t;
    ++out.frames;
  }
  const int status = ::pclose(renderer);
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.rc = status == -1 ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return out;
}

// The finished video's line (or JSON), the recordings' truncation or damage; the exit status.
int reportVideo(const services::CommandLine& cli, const VideoRequest& r, const Rendered& v,
                const std::vector<std::unique_ptr<Panel>>& panels) {
  bool corrupt = false;
  for (const auto& p : panels) {
    if (p->reader().end() == rawlog::RawlogReader::End::Truncated)
      std::fprintf(stderr, "mft-export: %s is truncated: drawn up to its last whole record\n", p->path().c_str());
    if (p->reader().end() == rawlog::RawlogReader::End::Corrupt) {
      std::fprintf(stderr, "mft-export: %s is %s: drawn up to the damage\n", p->path().c_str(), p->reader().endMessage().c_str());
      corrupt = true;
    }
  }
  const double video_s = static_cast<double>(v.frames) / static_cast<double>(r.fps);
  const double bytes = static_cast<double>(fs::file_size(r.out));
  const double rate = static_cast<double>(v.frames) / std::max(v.wall_s, 1e-9);
  if (cli.isSet("json")) {
    config::JsonWriter w;
    w.beginObject().field("video", r.out).field("format", r.ext.substr(1)).field("frames", v.frames).field("fps", r.fps);
    w.field("speed", r.speed, kPosition).fixedField("from_s", r.from, 6).fixedField("last_frame_s", v.last_t, 6);
    w.fixedField("video_s", video_s, 6).field("panels", panels.size()).fixedField("bytes", bytes, 0);
    w.fixedField("wall_s", v.wall_s, 3).fixedField("frames_per_s", rate, 2);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("video      %s: %ld frames at %ld fps = %.2f s of video for %.3f-%.3f s of the run (x%g), %zu panel%s, "
                "%.2f MB, rendered in %.1f s (%.1f frames/s)\n",
                r.out.c_str(), v.frames, r.fps, video_s, r.from, v.last_t + r.speed / static_cast<double>(r.fps), r.speed,
                panels.size(), panels.size() > 1 ? "s" : "", bytes / 1e6, v.wall_s, rate);
  }
  return corrupt ? kExitCorrupt : 0;
}

}  // namespace

int videoMain(const services::CommandLine& cli, const std::string& file) {
  VideoRequest r;
  if (const int rc = videoRequest(cli, &r)) return rc;
  std::vector<std::unique_ptr<Panel>> panels;
  double expected_end = 0.0;
  if (const int rc = openPanels(cli, file, r, &panels, &expected_end)) return rc;

  // Written under a temporary name in the same folder and renamed when complete: an interrupted or failed
  // render never leaves a partial video under the requested name.
  const fs::path out_path(r.out);
  const fs::path dir = out_path.has_parent_path() ? out_path.parent_path() : fs::path(".");
  const std::string tmp = (dir / ("." + out_path.filename().string() + ".partial-" + std::to_string(::getpid()))).string();
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) {
    std::fprintf(stderr, "mft-export: cannot write %s: %s\n", r.out.c_str(), std::strerror(errno));
    return kExitBadInput;
  }
  ::close(fd);
  auto removeTmp = [&] { ::unlink(tmp.c_str()); };
  const std::string header = headerLine(cli, r, tmp, panels, expected_end);

  // The renderer: python3-matplotlib draws each frame and pipes it into ffmpeg (docs/guide/videos.md).
  std::signal(SIGPIPE, SIG_IGN);  // a renderer that died shows as a failed write, not as our death
  services::installShutdownHandlers();
  const std::string script = config::dataFileFor("scripts/mft-video.py", MFT_VIDEO_SCRIPT);
  const std::string cmd = "/usr/bin/python3 " + shellQuote(script);
  std::FILE* renderer = ::popen(cmd.c_str(), "w");
  if (!renderer) {
    removeTmp();
    std::fprintf(stderr, "mft-export: cannot start the renderer (%s): %s\n", cmd.c_str(), std::strerror(errno));
    return kExitBadInput;
  }
  const Rendered v = renderFrames(header, r, panels, renderer);
  if (v.interrupted || services::shutdownRequested()) {
    removeTmp();
    std::fprintf(stderr, "mft-export: interrupted: no video written\n");
    return kExitInterrupted;
  }
  if (v.rc != 0) {
    removeTmp();
    // The renderer said why on stderr (its messages start with "mft-export:").
    if (v.rc != kExitBadInput) std::fprintf(stderr, "mft-export: the renderer failed (exit status %d): no video written\n", v.rc);
    return kExitBadInput;
  }
  if (v.frames == 0) {
    removeTmp();
    double end = 0.0;
    for (const auto& p : panels) end = std::max(end, p->hasSample() ? p->sampleTime() : 0.0);
    cli.fail("--from " + cli.get("from") + " s is not before the end of the recording (" + seconds(end) + ")");
  }
  const std::string cut = r.ext == ".mp4" ? incompleteMp4(tmp) : "";
  if (!cut.empty()) {
    removeTmp();
    std::fprintf(stderr, "mft-export: the encoder left %s incomplete (%s; disk full?): no video written\n",
                 r.out.c_str(), cut.c_str());
    return kExitBadInput;
  }
  fs::rename(tmp, r.out);
  return reportVideo(cli, r, v, panels);
}

}  // namespace mft::video
