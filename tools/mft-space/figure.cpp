#include "figure.hpp"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "json_writer.hpp"

namespace mft::tools {

using namespace mft::model;

namespace {
std::string gridJson(const LabelGrid& g) {
  std::string labels;
  labels.reserve(g.labels.size());
  for (auto l : g.labels) labels += static_cast<char>('0' + l);
  auto axis = [](const GridAxis& a) { return JsonObject().num("lo", a.lo).num("step", a.step).num("n", a.n).str(); };
  return JsonObject().raw("x", axis(g.x)).raw("y", axis(g.y)).str("labels", labels).str();
}
std::string pointsJson(const std::vector<Eigen::Vector2d>& pts) {
  std::string s = "[";
  for (std::size_t i = 0; i < pts.size(); ++i)
    s += (i ? ", [" : "[") + jsonNumber(pts[i].x()) + ", " + jsonNumber(pts[i].y()) + "]";
  return s + "]";
}
// Shell-quotes one argument for std::system.
std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}
}  // namespace

void writeFigureData(const std::string& path, const FigureInput& in) {
  // The polygon's image in foot space: walk its boundary in joint space and map every point by FK.
  const MftLegModel leg = MftLegModel::from(*in.robot);
  std::vector<Eigen::Vector2d> image;
  const auto& v = in.polygon->vertices;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d a = v[i], b = v[(i + 1) % v.size()];
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d q = a + (b - a) * (k / 200.0);
      FiveBarPose p;
      if (fiveBarForward(leg.geometry, q.x(), q.y(), &p) == FiveBarStatus::Ok) image.push_back(p.foot);
    }
  }
  const auto& c = *in.criteria;
  const std::string json =
      JsonObject()
          .str("robot", in.robot->name)
          .raw("joint", gridJson(*in.joint))
          .raw("cartesian", gridJson(*in.cartesian))
          .raw("polygon", pointsJson(v))
          .raw("polygon_cartesian", pointsJson(image))
          .raw("lti", "[" + jsonNumber(c.lti.lo) + ", " + jsonNumber(c.lti.hi) + "]")
          .raw("raci", "[" + jsonNumber(c.raci.lo) + ", " + jsonNumber(c.raci.hi) + "]")
          .str("raci_form", raciFormName(c.raci_options.form))
          .num("accel_max", c.raci_options.accel_max_mps2)
          .raw("rear_hip", "[" + jsonNumber(in.robot->rear_hip_rad.lo) + ", " + jsonNumber(in.robot->rear_hip_rad.hi) + "]")
          .raw("fore_hip", "[" + jsonNumber(in.robot->fore_hip_rad.lo) + ", " + jsonNumber(in.robot->fore_hip_rad.hi) + "]")
          .num("coverage", in.coverage)
          .num("r_max", in.r_max)
          .num("area", in.area)
          .str();
  std::ofstream out(path);
  out << json << "\n";
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::string drawFigure(const std::string& data_path, const std::string& png_path, const std::string& script) {
  const char* python = "/usr/bin/python3";
  if (std::system(nullptr) == 0) return "no shell available to run " + std::string(python);
  if (!std::ifstream(python)) return std::string(python) + " not found: figure skipped";
  if (!std::ifstream(script)) return "figure script " + script + " not found: figure skipped";
  const std::string cmd = std::string(python) + " " + quote(script) + " " + quote(data_path) + " " + quote(png_path);
  const int status = std::system(cmd.c_str());
  if (status == -1) return "could not run " + cmd;
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3) return "matplotlib is missing for /usr/bin/python3 (apt install python3-matplotlib): figure skipped";
  if (code != 0) return "the figure script failed (exit " + std::to_string(code) + "): " + cmd;
  return "";
}

}  // namespace mft::tools
