// Runs the MFT-WBC on a recorded state, outside the DDS stack: load the robot, the WBC configuration and the
// MFT polytope, feed the controller each recorded tick (state estimate + planner reference) in order, and
// print the joint torques it commands. Exit status: 0 every tick solved, 1 the controller failed on a tick
// (QP not optimal or the safety stage took over), 2 bad input (options, files, columns).
//
//   wbc_on_recorded_state [--config-dir DIR] [--state FILE] [--json]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/mft_polytope.hpp"
#include "model/robot_description.hpp"
#include "wbc/wbc_config.hpp"
#include "wbc/whole_body_controller.hpp"

namespace {

// One CSV row by column name.
using Row = std::map<std::string, double>;

std::vector<Row> readStateFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open the state file " + path);
  std::string line;
  std::vector<std::string> names;
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    if (names.empty()) {
      names = cells;
      continue;
    }
    if (cells.size() != names.size())
      throw std::runtime_error(path + ": a row has " + std::to_string(cells.size()) + " cells, the header " +
                               std::to_string(names.size()));
    Row row;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      std::size_t used = 0;
      row[names[i]] = std::stod(cells[i], &used);
      if (used != cells[i].size()) throw std::runtime_error(path + ": not a number: '" + cells[i] + "'");
    }
    rows.push_back(row);
  }
  if (rows.empty()) throw std::runtime_error(path + ": no rows");
  return rows;
}

double column(const Row& row, const std::string& name) {
  const auto it = row.find(name);
  if (it == row.end()) throw std::runtime_error("the state file has no column '" + name + "'");
  return it->second;
}

// The generalized coordinates in the order of mft::model::VectorQ (model/coordinates.hpp), as the rawlog names them.
const char* const kQ[mft::model::kNq] = {"x", "z", "pitch", "q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"};
const char* const kQd[mft::model::kNq] = {"xd",  "zd",  "pitchd", "qd4",  "qd5", "qd6",
                                          "qd7", "qd8", "qd9",    "qd10", "qd11"};

mft::model::RobotStateEstimate stateOf(const Row& row) {
  mft::model::RobotStateEstimate s;
  s.tick = static_cast<std::uint64_t>(column(row, "tick"));
  for (int i = 0; i < mft::model::kNq; ++i) {
    s.q[i] = column(row, kQ[i]);
    s.qd[i] = column(row, kQd[i]);
  }
  s.contact = {column(row, "contact_right") != 0.0, column(row, "contact_left") != 0.0};
  return s;
}

mft::wbc::WbcReference referenceOf(const Row& row) {
  mft::wbc::WbcReference r;
  r.tick = static_cast<std::uint64_t>(column(row, "tick"));
  r.foot_in_stance = {column(row, "in_stance_right") != 0.0, column(row, "in_stance_left") != 0.0};
  r.base_z = {column(row, "base_z"), column(row, "base_zd"), column(row, "base_zdd")};
  r.base_pitch = {column(row, "pitch_ref"), column(row, "pitchd_ref"), column(row, "pitchdd_ref")};
  r.base_x = {column(row, "base_x"), column(row, "base_xd"), column(row, "base_xdd")};
  r.hold_base_x = column(row, "hold_base_x") != 0.0;
  // World [x, z] of the right foot, then the left.
  r.foot_pos << column(row, "foot_x_right"), column(row, "foot_z_right"), column(row, "foot_x_left"),
      column(row, "foot_z_left");
  r.foot_vel << column(row, "foot_vx_right"), column(row, "foot_vz_right"), column(row, "foot_vx_left"),
      column(row, "foot_vz_left");
  r.foot_acc << column(row, "foot_ax_right"), column(row, "foot_az_right"), column(row, "foot_ax_left"),
      column(row, "foot_az_left");
  return r;
}

int run(int argc, char** argv) {
  std::string config_dir = EXAMPLE_CONFIG_DIR;
  std::string state_file = EXAMPLE_STATE_FILE;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf("usage: wbc_on_recorded_state [--config-dir DIR] [--state FILE] [--json]\n"
                  "Runs the MFT-WBC on each tick of a recorded state file and prints the joint torques.\n"
                  "  --config-dir DIR  robot.yaml, wbc.yaml, mft_space.yaml (default %s)\n"
                  "  --state FILE      recorded ticks, CSV with named columns (default %s)\n"
                  "  --json            one JSON object on stdout (torques at full precision)\n"
                  "Exit status: 0 every tick solved, 1 the controller failed on a tick, 2 bad input.\n",
                  EXAMPLE_CONFIG_DIR, EXAMPLE_STATE_FILE);
      return 0;
    } else if (a == "--json") {
      json = true;
    } else if ((a == "--config-dir" || a == "--state") && i + 1 < argc) {
      (a == "--state" ? state_file : config_dir) = argv[++i];
    } else {
      std::fprintf(stderr, "wbc_on_recorded_state: error: unknown or incomplete option '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }

  const mft::model::RobotDescription robot = mft::model::loadRobotDescription(config_dir + "/robot.yaml");
  const mft::wbc::WbcConfig config = mft::wbc::loadWbcConfig(config_dir + "/wbc.yaml");
  const mft::model::MftPolytope polytope = mft::model::loadMftPolytope(config_dir + "/mft_space.yaml", robot);
  const std::vector<Row> rows = readStateFile(state_file);
  mft::wbc::WholeBodyController controller(robot, config, &polytope);
  const double torque_limit = config.limits.torque_limit_fraction * robot.actuator.outputPeakTorque();

  int failed = 0;
  double max_abs_tau = 0.0;
  std::string ticks_json;
  if (!json) std::printf("%8s %12s %12s %12s %12s  %s\n", "tick", "tau_q4", "tau_q6", "tau_q8", "tau_q10", "status");
  for (const Row& row : rows) {
    mft::wbc::WbcDiagnostics diag;
    const mft::model::ActuatorCommand cmd = controller.update(stateOf(row), referenceOf(row), &diag);
    const bool ok = diag.status == mft::qp::QpStatus::Optimal &&
                    diag.safety_event == mft::wbc::SafetyEvent::None && cmd.mode == mft::model::CommandMode::Normal;
    failed += ok ? 0 : 1;
    for (int j = 0; j < mft::model::kNa; ++j) max_abs_tau = std::max(max_abs_tau, std::abs(cmd.tau[j]));
    const char* status = ok ? "ok" : mft::wbc::toString(diag.safety_event);
    if (json) {
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "%s{\"tick\": %llu, \"tau\": [%.17g, %.17g, %.17g, %.17g], \"ok\": %s, \"status\": \"%s\"}",
                    ticks_json.empty() ? "" : ", ", static_cast<unsigned long long>(cmd.tick), cmd.tau[0], cmd.tau[1],
                    cmd.tau[2], cmd.tau[3], ok ? "true" : "false", status);
      ticks_json += buf;
    } else {
      std::printf("%8llu %12.6f %12.6f %12.6f %12.6f  %s\n", static_cast<unsigned long long>(cmd.tick), cmd.tau[0],
                  cmd.tau[1], cmd.tau[2], cmd.tau[3], status);
    }
  }
  if (json) {
    std::printf("{\"config_dir\": \"%s\", \"state_file\": \"%s\", \"variant\": \"%s\", \"torque_limit_Nm\": %.17g, "
                "\"max_abs_tau_Nm\": %.17g, \"failed_ticks\": %d, \"ticks\": [%s]}\n",
                config_dir.c_str(), state_file.c_str(), mft::wbc::toString(controller.variant()), torque_limit,
                max_abs_tau, failed, ticks_json.c_str());
  } else {
    std::printf("%zu ticks, %d failed; max |tau| %.3f N m (limit %.3f N m)\n", rows.size(), failed, max_abs_tau,
                torque_limit);
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wbc_on_recorded_state: error: %s\n", e.what());
    return 2;
  }
}
