// mft-space: the offline MFT preferable space of the five-bar legs (paper sec. III-B, docs/five-bar-theory.md#the-polygon-fit).
// Exit codes: 0 done, 1 the work failed (fit, file output, figure on `figure`), 2 bad arguments or bad config.
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <string>

#include "cli_args.hpp"
#include "figure.hpp"
#include "json_writer.hpp"
#include "common/strict_yaml.hpp"
#include "space_run.hpp"
#include "stance_table.hpp"
#include "common/tool_io.hpp"

using namespace mft::model;
using namespace mft::tools;

namespace {

const char* kUsage = R"(usage: mft-space <command> [options]

commands
  fit      grid the leg's reachable space, fit the conservative polygon, write the polytope YAML
  figure   draw the paper's Fig. 5 (PNG) for a stored polytope
  stance   LTI, RACI and polygon membership along the vertical stance
  index    LTI (input/output indices) and RACI of one configuration
  all      fit + figure + stance table into --out DIR (mft_space.yaml, mft_space.png, stance.txt)

common options
  --robot FILE        robot description (default: <config>/robot.yaml)
  --json              machine-readable output on stdout (progress stays on stderr)
  --quiet             no progress on stderr

fit / all
  --output FILE       polytope YAML (fit default: <config>/mft_space.yaml; all: also DIR/mft_space.yaml)
  --out DIR           (all) output folder, created if missing
  --joint-step RAD    joint-space grid step (default 0.01)
  --cart-step M       Cartesian grid step (default 0.01 = the paper's 10 x 10 mm)
  --edges N           polygon edges (default 6; only a hexagon gives the WBC's 12 x 4 polytope)
  --starts N          random starts of the fit (default 24)   --seed N   RNG seed (default 1)
index / fit / all (thresholds and RACI)
  --lti-min X --lti-max X      LTI range (default 0.7 .. 1)
  --raci-min X --raci-max X    RACI range in N/sqrt(kg) (default 0 .. T_m,max/sqrt(J_m) of the actuator)
  --accel A           desired foot acceleration bound a_max (default 60 m/s^2)
  --raci-form F       optimal (default, optimal gear ratio) or fixed (k = n sqrt(J_m) of the actuator)
  --drive-k K         override k for the fixed form       --gravity   include gravity in RACI
figure / stance
  --polytope FILE     stored polytope (default: <config>/mft_space.yaml)
  --png FILE          (figure) output PNG (default mft_space.png)
  --from M --to M --step M     (stance) base heights (default 0.38 .. 0.46 step 0.01)
index
  --rear Q4 --fore Q6 actuated hip angles [rad] (required)
)";

// The configuration folder of this executable: the source tree's, or <prefix>/share/mft_wbc/config installed.
std::string configDir() { return mft::config::configDirFor(MFT_CONFIG_DIR); }
std::string defaultRobot() { return configDir() + "/robot.yaml"; }
std::string defaultPolytope() { return configDir() + "/mft_space.yaml"; }
std::string figureScript() { return mft::config::dataFileFor("scripts/mft_space_figure.py", MFT_SPACE_FIGURE_SCRIPT); }

// kUsage with <config> replaced by the configuration folder.
std::string usage() {
  std::string text = kUsage;
  const std::string token = "<config>";
  for (std::size_t at = text.find(token); at != std::string::npos; at = text.find(token, at))
    text.replace(at, token.size(), configDir());
  return text;
}

std::set<std::string> withSpaceOptions(std::set<std::string> s) {
  for (int i = 0; kSpaceOptions[i]; ++i) s.insert(kSpaceOptions[i]);
  return s;
}
const std::set<std::string> kCommonFlags = {"json", "quiet"};
std::set<std::string> flagsWith(std::set<std::string> s) {
  s.insert(kCommonFlags.begin(), kCommonFlags.end());
  return s;
}

void makeDir(const std::string& dir) {
  std::string partial;
  for (std::size_t i = 0; i <= dir.size(); ++i) {
    if (i == dir.size() || dir[i] == '/') {
      if (!partial.empty() && ::mkdir(partial.c_str(), 0755) != 0 && errno != EEXIST)
        throw std::runtime_error("cannot create folder " + partial + ": " + std::strerror(errno));
    }
    if (i < dir.size()) partial += dir[i];
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) throw std::runtime_error(dir + " is not a folder");
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::string pngDataPath(const std::string& png) {
  const std::string stem = png.size() > 4 && png.substr(png.size() - 4) == ".png" ? png.substr(0, png.size() - 4) : png;
  return stem + "_data.json";
}

FigureInput figureInput(const LabelGrid& joint, const LabelGrid& cart, const MftPolytope& p, const RobotDescription& r) {
  FigureInput in;
  in.joint = &joint;
  in.cartesian = &cart;
  in.polygon = &p.leg;
  in.criteria = &p.criteria;
  in.robot = &r;
  in.coverage = p.fit.coverage;
  in.r_max = p.fit.r_max_rad;
  in.area = p.fit.area_rad2;
  return in;
}

int cmdFit(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, withSpaceOptions({"robot", "output"}), flagsWith({"gravity"}));
  Progress progress(a.flag("quiet"));
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const SpaceSettings s = settingsFromArgs(a, robot);
  const SpaceResult r = runSpace(robot, s, progress);
  const std::string output = a.text("output", defaultPolytope());
  writePolytopeFile(output, r, robot);
  progress.stage("wrote " + output);
  if (a.flag("json")) {
    std::cout << JsonWriter().beginObject().field("output", output).key("fit").raw(summaryJson(r)).endObject().str() << "\n";
  } else {
    std::cout << summaryText(r) << "written         " << output << "\n";
    if (!r.has_augmented) std::cout << "note            not a hexagon: the WBC loader accepts only 6 edges\n";
  }
  return 0;
}

int cmdFigure(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, {"robot", "polytope", "png"}, flagsWith({}));
  Progress progress(a.flag("quiet"));
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const MftPolytope p = loadMftPolytope(a.text("polytope", defaultPolytope()), robot);
  LabelGrid joint, cart;
  gridSpaces(robot, p.criteria, p.fit.joint_step_rad, p.fit.cartesian_step_m, progress, &joint, &cart);
  const std::string png = a.text("png", "mft_space.png");
  const std::string data = pngDataPath(png);
  writeFigureData(data, figureInput(joint, cart, p, robot));
  progress.stage("drawing " + png);
  const std::string why = drawFigure(data, png, figureScript());
  if (a.flag("json"))
    std::cout << JsonWriter().beginObject().field("png", png).field("data", data).field("drawn", why.empty()).field("error", why).endObject().str()
              << "\n";
  else
    std::cout << (why.empty() ? "figure written to " + png : "figure NOT drawn: " + why) << "\n";
  if (!why.empty()) std::cerr << "mft-space: " << why << "\n";
  return why.empty() ? 0 : 1;
}

void stanceRange(const CliArgs& a, double* from, double* to, double* step) {
  *from = a.positive("from", 0.38);
  *to = a.positive("to", 0.46);
  *step = a.positive("step", 0.01);
  if (*to < *from) throw UsageError("--to must not be below --from");
  if ((*to - *from) / *step > 10000) throw UsageError("--step too small: more than 10000 rows");
}

int cmdStance(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, {"robot", "polytope", "from", "to", "step"}, flagsWith({}));
  double from, to, step;
  stanceRange(a, &from, &to, &step);
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const MftPolytope p = loadMftPolytope(a.text("polytope", defaultPolytope()), robot);
  const auto rows = stanceTable(robot, p.criteria, p.leg, from, to, step);
  std::cout << (a.flag("json") ? stanceJson(rows) + "\n" : stanceText(rows, p.criteria));
  return 0;
}

int cmdIndex(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, withSpaceOptions({"robot", "rear", "fore"}), flagsWith({"gravity"}));
  const std::string rear = a.required("rear"), fore = a.required("fore");
  const double q_rear = a.number("rear", 0.0), q_fore = a.number("fore", 0.0);
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const MftCriteria c = criteriaFromArgs(a, robot);
  const LegEvaluation e = evaluateLegAt(MftLegModel::from(robot), c, q_rear, q_fore);
  std::cout << (a.flag("json") ? indexJson(e, c) + "\n" : indexText(e, c));
  return 0;
}

int cmdAll(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, withSpaceOptions({"robot", "output", "out", "from", "to", "step"}),
                  flagsWith({"gravity"}));
  const std::string dir = a.required("out");
  double from, to, step;
  stanceRange(a, &from, &to, &step);
  Progress progress(a.flag("quiet"));
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const SpaceSettings s = settingsFromArgs(a, robot);
  makeDir(dir);
  const SpaceResult r = runSpace(robot, s, progress);
  const std::string yaml = dir + "/mft_space.yaml";
  writePolytopeFile(yaml, r, robot);
  if (a.has("output")) writePolytopeFile(a.text("output", ""), r, robot);
  progress.stage("wrote " + yaml);

  const std::string png = dir + "/mft_space.png", data = dir + "/mft_space_data.json";
  writeFigureData(data, figureInput(r.joint, r.cartesian, r.polytope, robot));
  progress.stage("drawing " + png);
  const std::string why = drawFigure(data, png, figureScript());
  if (!why.empty()) std::cerr << "mft-space: WARNING: " << why << "\n";

  const auto rows = stanceTable(robot, s.criteria, r.polytope.leg, from, to, step);
  const std::string table = stanceText(rows, s.criteria);
  writeText(dir + "/stance.txt", table);
  writeText(dir + "/stance.json", stanceJson(rows) + "\n");
  writeText(dir + "/summary.json", summaryJson(r) + "\n");
  progress.stage("wrote " + dir + "/stance.txt, stance.json, summary.json");
  if (a.flag("json")) {
    std::cout << JsonWriter().beginObject()
                     .field("out", dir)
                     .field("yaml", yaml)
                     .field("png", why.empty() ? png : "")
                     .field("figure_error", why)
                     .key("fit").raw(summaryJson(r))
                     .key("stance").raw(stanceJson(rows))
                     .field("seconds", progress.seconds(), kDigits)
                     .endObject().str()
              << "\n";
  } else {
    std::cout << summaryText(r) << "\n" << table << "\nwritten to " << dir << ": mft_space.yaml, "
              << (why.empty() ? "mft_space.png, " : "") << "stance.txt, stance.json, summary.json (total "
              << static_cast<int>(progress.seconds() * 100.0 + 0.5) / 100.0 << " s)\n";
  }
  return 0;
}

}  // namespace

static int toolMain(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "mft-space: missing command\n" << usage();
    return 2;
  }
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::cout << usage();
    return 0;
  }
  try {
    if (cmd == "fit") return cmdFit(argc, argv);
    if (cmd == "figure") return cmdFigure(argc, argv);
    if (cmd == "stance") return cmdStance(argc, argv);
    if (cmd == "index") return cmdIndex(argc, argv);
    if (cmd == "all") return cmdAll(argc, argv);
    std::cerr << "mft-space: unknown command '" << cmd << "' (fit, figure, stance, index, all; see --help)\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "mft-space " << cmd << ": " << e.what() << "\n";
    return 2;
  } catch (const mft::config::ConfigError& e) {
    std::cerr << "mft-space " << cmd << ": bad configuration: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mft-space " << cmd << ": " << e.what() << "\n";
    return 1;
  }
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-space", [&] { return toolMain(argc, argv); });
}
