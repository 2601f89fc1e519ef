#include "model/mft_grid.hpp"

#include <algorithm>
#include <cmath>

namespace mft::model {

int LabelGrid::count(std::uint8_t label) const {
  return static_cast<int>(std::count(labels.begin(), labels.end(), label));
}
int LabelGrid::countAtLeast(std::uint8_t label) const {
  return static_cast<int>(std::count_if(labels.begin(), labels.end(), [&](std::uint8_t l) { return l >= label; }));
}

namespace {
GridAxis axisOver(const Interval& range, double step) {
  return {range.lo, step, static_cast<int>(std::floor((range.hi - range.lo) / step + 1e-9)) + 1};
}
std::uint8_t labelOf(const LegEvaluation& e) {
  return e.preferable ? kCellPreferable : (e.reachable ? kCellReachable : kCellUnreachable);
}
template <typename Eval>
LabelGrid fill(GridAxis x, GridAxis y, const Eval& eval, const GridProgress& progress) {
  LabelGrid g;
  g.x = x;
  g.y = y;
  g.labels.assign(static_cast<std::size_t>(x.n) * y.n, kCellUnreachable);
  for (int j = 0; j < y.n; ++j) {
    for (int i = 0; i < x.n; ++i) g.labels[static_cast<std::size_t>(j) * x.n + i] = labelOf(eval(x.at(i), y.at(j)));
    if (progress) progress(j + 1, y.n);
  }
  return g;
}
}  // namespace

LabelGrid gridJointSpace(const MftLegModel& m, const MftCriteria& c, double step, const GridProgress& progress) {
  return fill(axisOver(m.rear_hip, step), axisOver(m.fore_hip, step),
              [&](double qr, double qf) { return evaluateLegAt(m, c, qr, qf); }, progress);
}

LabelGrid gridCartesianSpace(const MftLegModel& m, const MftCriteria& c, double step, const GridProgress& progress) {
  const double reach = m.geometry.l1 + m.geometry.l2 + 0.5 * m.geometry.hip_spacing;
  const int half = static_cast<int>(std::ceil(reach / step - 1e-9));
  const GridAxis axis{-half * step, step, 2 * half + 1};
  return fill(axis, axis, [&](double x, double z) { return evaluateLegAtFoot(m, c, {x, z}); }, progress);
}

}  // namespace mft::model
