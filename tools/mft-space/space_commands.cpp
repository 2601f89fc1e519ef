// mft-space's commands (main.cpp dispatches): each parses its own options, runs, prints text or --json.
#include "space_commands.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <stdexcept>

#include "cli_args.hpp"
#include "common/tool_io.hpp"
#include "figure.hpp"
#include "json_writer.hpp"
#include "progress.hpp"
#include "space_run.hpp"
#include "stance_table.hpp"
#include "violation_table.hpp"

using namespace mft::model;

namespace mft::tools {

namespace {

std::string defaultRobot() { return configDir() + "/robot.yaml"; }
std::string defaultPolytope() { return configDir() + "/mft_space.yaml"; }
std::string figureScript() { return mft::config::dataFileFor("scripts/mft_space_figure.py", MFT_SPACE_FIGURE_SCRIPT); }

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

}  // namespace

int cmdFit(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, withSpaceOptions({"robot", "output"}), flagsWith({"gravity"}));
  Progress progress(a.flag("quiet"));
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const MftSpaceSettings s = settingsFromArgs(a, robot);
  const MftSpaceResult r = fitMftSpace(robot, s, progress.callbacks());
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
  gridMftSpaces(robot, p.criteria, p.fit.joint_step_rad, p.fit.cartesian_step_m, progress.callbacks(), &joint, &cart);
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

static void stanceRange(const CliArgs& a, double* from, double* to, double* step) {
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
  const MftSpaceSettings s = settingsFromArgs(a, robot);
  makeDir(dir);
  const MftSpaceResult r = fitMftSpace(robot, s, progress.callbacks());
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

// A CSV with the columns q4, q6, q8, q10 (mft-export's gt_q.csv) to the paper's (10) per row, for each leg and
// for the augmented polytope, by the model's one function; the columns stamp_ns, time_s and tick pass through.
int cmdViolation(int argc, char** argv) {
  const CliArgs a(argc, argv, 2, {"robot", "polytope", "csv", "output"}, {"json"});
  const std::string in_path = a.required("csv");
  const RobotDescription robot = loadRobotDescription(a.text("robot", defaultRobot()));
  const MftPolytope p = loadMftPolytope(a.text("polytope", defaultPolytope()), robot);
  std::ifstream in(in_path);
  if (!in) throw UsageError("--csv: cannot read " + in_path);
  const ViolationTable t = violationTable(in, in_path, p);
  const std::string out_path = a.text("output", "");
  std::ofstream file;
  if (!out_path.empty()) {
    file.open(out_path);
    if (!file) throw std::runtime_error("cannot write " + out_path);
  }
  std::ostream& out = out_path.empty() ? std::cout : file;
  writeViolationCsv(out, t);
  if (!out_path.empty()) {
    file.close();
    if (!file) throw std::runtime_error("cannot write " + out_path);
  }
  if (a.flag("json") && !out_path.empty())
    std::cout << JsonWriter().beginObject().field("output", out_path).field("rows", static_cast<long long>(t.rows.size()))
                     .field("max_violation", t.max_violation, kDigits).endObject().str() << "\n";
  return 0;
}

std::string configDir() { return mft::config::configDirFor(MFT_CONFIG_DIR); }

}  // namespace mft::tools
