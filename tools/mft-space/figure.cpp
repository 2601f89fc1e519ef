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
  auto axis = [](const GridAxis& a) { return JsonWriter().beginObject().field("lo", a.lo, kDigits).field("step", a.step, kDigits).field("n", a.n, kDigits).str(); };
  return JsonWriter().beginObject().key("x").raw(axis(g.x)).key("y").raw(axis(g.y)).field("labels", labels).endObject().str();
}
std::string pointsJson(const std::vector<Eigen::Vector2d>& pts) {
  JsonWriter w;
  w.beginArray();
  for (const auto& p : pts) w.numbers({p.x(), p.y()}, kDigits);
  return w.endArray().str();
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
      JsonWriter().beginObject()
          .field("robot", in.robot->name)
          .key("joint").raw(gridJson(*in.joint))
          .key("cartesian").raw(gridJson(*in.cartesian))
          .key("polygon").raw(pointsJson(v))
          .key("polygon_cartesian").raw(pointsJson(image))
          .key("lti").raw(JsonWriter().numbers({c.lti.lo, c.lti.hi}, kDigits).str())
          .key("raci").raw(JsonWriter().numbers({c.raci.lo, c.raci.hi}, kDigits).str())
          .field("raci_form", raciFormName(c.raci_options.form))
          .field("accel_max", c.raci_options.accel_max_mps2, kDigits)
          .key("rear_hip").raw(JsonWriter().numbers({in.robot->rear_hip_rad.lo, in.robot->rear_hip_rad.hi}, kDigits).str())
          .key("fore_hip").raw(JsonWriter().numbers({in.robot->fore_hip_rad.lo, in.robot->fore_hip_rad.hi}, kDigits).str())
          .field("coverage", in.coverage, kDigits)
          .field("r_max", in.r_max, kDigits)
          .field("area", in.area, kDigits)
          .endObject().str();
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
