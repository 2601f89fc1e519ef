#pragma once
// The project's QP instance set (tests/data/qp, format and origin in docs/reference/qp-instances.md), loaded once per test
// binary, and what the tests ask of an instance: its run and which constraint kinds are active in its reference.
#include <string>
#include <utility>
#include <vector>

#include "wbc/qp/qp_io.hpp"

namespace mft::qp::testing {

inline std::string instanceDir() { return std::string(MFT_TEST_DATA_DIR) + "/qp"; }

// Every instance in file-name order: runs one after the other, each run's ticks consecutive.
inline const std::vector<QpInstance>& instanceSet() {
  static const std::vector<QpInstance> instances = [] {
    std::vector<QpInstance> v;
    for (const std::string& f : listQpInstanceFiles(instanceDir())) v.push_back(readQpInstance(f));
    return v;
  }();
  return instances;
}

// One instance by name (file stem); throws QpIoError if it is not in the set.
inline const QpInstance& instanceNamed(const std::string& name) {
  for (const QpInstance& inst : instanceSet())
    if (inst.name == name) return inst;
  throw QpIoError("no QP instance named " + name + " in " + instanceDir());
}

// The run an instance belongs to: its name without the trailing _<tick>.
inline std::string runOf(const QpInstance& inst) { return inst.name.substr(0, inst.name.rfind('_')); }

// The constraint kinds the instance has, each with whether the reference active set uses it: every "in_*" row
// block (the friction pyramid of a stance foot only), the qdd box of the base and of the joints, and f_z >= 0 /
// f_z <= max of a stance foot (a swing foot's f_z is fixed to 0: an equality, not listed). Layout as written by
// the WBC: f_c = [f_x, f_z] per foot, friction rows two per foot in the same order.
inline std::vector<std::pair<std::string, bool>> activeKinds(const QpInstance& inst) {
  std::vector<std::pair<std::string, bool>> kinds;
  const Eigen::VectorXi& active = *inst.active_ref;
  const QpProblem& p = inst.problem;
  int fc_first = -1;
  for (const QpBlock& b : inst.varblocks)
    if (b.name == "f_c") fc_first = b.first;
  auto stance = [&](int foot) { return fc_first >= 0 && p.lb[fc_first + 2 * foot + 1] != p.ub[fc_first + 2 * foot + 1]; };
  for (const QpBlock& b : inst.rowblocks) {
    if (b.name.rfind("in_", 0) != 0) continue;
    bool any = false;
    // A swing foot's pyramid rows are trivially tight (f_z = 0 forces f_x = 0): only a stance foot's count.
    const bool friction = b.name == "in_friction";
    for (int r = b.first; r < b.first + b.length; ++r)
      if (!friction || stance((r - b.first) / 2)) any = any || active[p.n + r] != 0;
    kinds.emplace_back(friction ? "in_friction (stance foot)" : b.name, any);
  }
  for (const QpBlock& b : inst.varblocks) {
    if (b.name == "qdd") {
      bool base = false, joint = false;
      for (int j = b.first; j < b.first + b.length; ++j) (j - b.first < 3 ? base : joint) |= active[j] != 0;
      kinds.emplace_back("bound qdd_base", base);
      kinds.emplace_back("bound qdd_joint", joint);
    } else if (b.name == "f_c") {
      bool lower = false, upper = false, has_stance = false;
      for (int j = b.first + 1; j < b.first + b.length; j += 2) {  // [f_x, f_z] per foot
        if (p.lb[j] == p.ub[j]) continue;
        has_stance = true;
        lower = lower || active[j] < 0;
        upper = upper || active[j] > 0;
      }
      if (has_stance) {
        kinds.emplace_back("bound f_z >= 0 (stance)", lower);
        kinds.emplace_back("bound f_z <= max (stance)", upper);
      }
    }
  }
  return kinds;
}

}  // namespace mft::qp::testing
