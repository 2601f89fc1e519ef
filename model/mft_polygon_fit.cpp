#include "model/mft_polygon_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace mft::model {

FitCells fitCellsFromGrid(const LabelGrid& g) {
  FitCells c;
  c.half = {0.5 * g.x.step, 0.5 * g.y.step};
  // Index with a one-cell frame: frame cells are bad.
  auto good = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < g.x.n && j < g.y.n && g.at(i, j) == kCellPreferable;
  };
  for (int j = -1; j <= g.y.n; ++j) {
    for (int i = -1; i <= g.x.n; ++i) {
      const Eigen::Vector2d centre = g.node(i, j);
      if (good(i, j)) {
        c.good.push_back(centre);
        continue;
      }
      bool touches_good = false;
      for (int dj = -1; dj <= 1 && !touches_good; ++dj)
        for (int di = -1; di <= 1 && !touches_good; ++di) touches_good = good(i + di, j + dj);
      if (touches_good) c.bad.push_back(centre);
    }
  }
  return c;
}

namespace {

constexpr double kLoose = 1e3;  // offset of an edge that no bad cell needs (kept inside the clip box)

// The fit state: angles, offsets and the exclusion thresholds s_jk of every bad cell for every edge.
struct State {
  HalfPlanePolygon poly;
  std::vector<std::vector<double>> s;  // s[k][j]
};

class Fitter {
 public:
  Fitter(const FitCells& c, const PolygonFitOptions& o, const Eigen::Vector2d& seed) : c_(c), o_(o), seed_(seed) {
    lo_ = hi_ = seed;
    for (const auto* set : {&c.good, &c.bad})
      for (const auto& p : *set) lo_ = lo_.cwiseMin(p), hi_ = hi_.cwiseMax(p);
    lo_ -= Eigen::Vector2d::Constant(1.0);
    hi_ += Eigen::Vector2d::Constant(1.0);
  }

  bool run(std::mt19937& rng, State* best) {
    State st;
    if (!initialise(rng, &st)) return false;
    if (!greedyShrink(&st)) return false;
    ascent(&st, -1);
    double area = st.poly.area();
    for (int round = 0; round < 4; ++round) {
      area = patternSearch(&st, area);
      const double cut = vertexCuts(&st, area);
      if (!(cut > area + 1e-12)) break;
      area = cut;
    }
    *best = std::move(st);
    return true;
  }

 private:
  double threshold(const Eigen::Vector2d& n, const Eigen::Vector2d& centre) const {
    return n.dot(centre) - (c_.half.x() * std::abs(n.x()) + c_.half.y() * std::abs(n.y())) - o_.margin;
  }
  void computeColumn(State* st, int k) const {
    const Eigen::Vector2d n = st->poly.normal(k);
    auto& col = st->s[k];
    col.resize(c_.bad.size());
    for (std::size_t j = 0; j < c_.bad.size(); ++j) col[j] = threshold(n, c_.bad[j]);
  }
  bool excluded(const State& st, std::size_t j, int skip) const {
    for (int k = 0; k < st.poly.size(); ++k)
      if (k != skip && st.s[k][j] >= st.poly.offset[k]) return true;
    return false;
  }
  // Largest feasible offset of edge k with the other edges fixed.
  double maxOffset(const State& st, int k) const {
    double b = kLoose;
    for (std::size_t j = 0; j < c_.bad.size(); ++j)
      if (st.s[k][j] < b && !excluded(st, j, k)) b = st.s[k][j];
    return b;
  }
  // Exact offset ascent; `last` (if >= 0) is raised after the others (used by vertex cuts).
  void ascent(State* st, int last) const {
    const int K = st->poly.size();
    for (bool changed = true; changed;) {
      changed = false;
      for (int step = 0; step < K; ++step) {
        const int k = last < 0 ? step : (last + 1 + step) % K;
        const double b = maxOffset(*st, k);
        if (b > st->poly.offset[k] + 1e-12) st->poly.offset[k] = b, changed = true;
      }
    }
  }
  bool initialise(std::mt19937& rng, State* st) const {
    const int K = o_.edges;
    std::uniform_real_distribution<double> rot(0.0, 2.0 * M_PI / K);
    const double r = rot(rng);
    st->poly.box_lo = lo_;
    st->poly.box_hi = hi_;
    st->poly.angle.resize(K);
    st->poly.offset.resize(K);
    st->s.resize(K);
    for (int k = 0; k < K; ++k) {
      st->poly.angle[k] = r + 2.0 * M_PI * k / K;
      const Eigen::Vector2d n = st->poly.normal(k);
      double b = n.dot(seed_);
      for (const auto& g : c_.good) b = std::max(b, n.dot(g) + c_.half.x() * std::abs(n.x()) + c_.half.y() * std::abs(n.y()));
      st->poly.offset[k] = b;
      computeColumn(st, k);
    }
    return true;
  }
  bool greedyShrink(State* st) const {
    std::vector<std::size_t> order(c_.bad.size());
    std::iota(order.begin(), order.end(), 0);
    std::vector<double> dist(c_.bad.size());
    for (std::size_t j = 0; j < c_.bad.size(); ++j) dist[j] = (c_.bad[j] - seed_).squaredNorm();
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return dist[a] < dist[b]; });
    for (std::size_t j : order) {
      if (excluded(*st, j, -1)) continue;
      int best_k = -1;
      double best_area = -1.0;
      for (int k = 0; k < st->poly.size(); ++k) {
        const double b = st->s[k][j];
        if (!(st->poly.normal(k).dot(seed_) < b)) continue;  // would cut off the seed
        const double keep = st->poly.offset[k];
        st->poly.offset[k] = b;
        const double a = st->poly.area();
        st->poly.offset[k] = keep;
        if (a > best_area) best_area = a, best_k = k;
      }
      if (best_k < 0) return false;
      st->poly.offset[best_k] = st->s[best_k][j];
    }
    return true;
  }
  double patternSearch(State* st, double area) const {
    for (double delta = o_.delta_start; delta >= o_.delta_min; delta *= 0.5) {
      for (bool improved = true; improved;) {
        improved = false;
        for (int k = 0; k < st->poly.size(); ++k) {
          for (double sign : {1.0, -1.0}) {
            State trial = *st;
            trial.poly.angle[k] += sign * delta;
            computeColumn(&trial, k);
            trial.poly.offset[k] = maxOffset(trial, k);
            ascent(&trial, -1);
            if (!trial.poly.contains(seed_)) continue;
            const double a = trial.poly.area();
            if (a > area + 1e-12) {
              *st = std::move(trial);
              area = a;
              improved = true;
            }
          }
        }
      }
    }
    return area;
  }
  // Re-seat edges that carry no polygon side through a vertex, near the bisector of the two edges there.
  double vertexCuts(State* st, double area) const {
    const int K = st->poly.size();
    for (int k = 0; k < K; ++k) {
      const auto v = st->poly.vertices();
      const double tol = 1e-9;
      int on_edge = 0;
      for (const auto& p : v) on_edge += std::abs(st->poly.normal(k).dot(p) - st->poly.offset[k]) < tol;
      if (on_edge >= 2) continue;
      State best = *st;
      double best_area = area;
      for (const auto& p : v) {
        Eigen::Vector2d bis = Eigen::Vector2d::Zero();
        for (int l = 0; l < K; ++l)
          if (l != k && std::abs(st->poly.normal(l).dot(p) - st->poly.offset[l]) < tol) bis += st->poly.normal(l);
        if (bis.norm() < 1e-12) continue;
        const double base = std::atan2(bis.y(), bis.x());
        for (double d : {-0.3, 0.0, 0.3}) {
          State trial = *st;
          trial.poly.angle[k] = base + d;
          computeColumn(&trial, k);
          trial.poly.offset[k] = trial.poly.normal(k).dot(p);
          ascent(&trial, k);
          if (!trial.poly.contains(seed_)) continue;
          const double a = trial.poly.area();
          if (a > best_area + 1e-12) best_area = a, best = std::move(trial);
        }
      }
      if (best_area > area) *st = std::move(best), area = best_area;
    }
    return area;
  }

  const FitCells& c_;
  const PolygonFitOptions& o_;
  Eigen::Vector2d seed_;
  Eigen::Vector2d lo_, hi_;
};

// Canonical form: angles wrapped to (-pi, pi], edges sorted by angle, redundant offsets tightened.
HalfPlanePolygon canonical(HalfPlanePolygon p) {
  p.tightenRedundant();
  std::vector<int> idx(p.size());
  std::iota(idx.begin(), idx.end(), 0);
  for (auto& a : p.angle) a = std::remainder(a, 2.0 * M_PI);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return p.angle[a] < p.angle[b]; });
  HalfPlanePolygon q = p;
  for (int k = 0; k < p.size(); ++k) q.angle[k] = p.angle[idx[k]], q.offset[k] = p.offset[idx[k]];
  return q;
}

}  // namespace

PolygonFitResult fitConservativePolygon(const FitCells& cells, const PolygonFitOptions& o) {
  PolygonFitResult r;
  if (o.edges < 3) {
    r.error = "a polygon needs at least 3 edges";
    return r;
  }
  if (cells.good.empty()) {
    r.error = "no preferable cell to fit";
    return r;
  }
  // The seed must be a good node so that every bad box can be separated from it by some edge.
  Eigen::Vector2d target = o.seed_point;
  if (!o.has_seed_point) {
    target.setZero();
    for (const auto& g : cells.good) target += g;
    target /= static_cast<double>(cells.good.size());
  }
  r.seed = *std::min_element(cells.good.begin(), cells.good.end(), [&](const auto& a, const auto& b) {
    return (a - target).squaredNorm() < (b - target).squaredNorm();
  });
  std::mt19937 rng(o.rng_seed);
  Fitter fitter(cells, o, r.seed);
  double best_area = -1.0;
  for (int s = 0; s < std::max(1, o.starts); ++s) {
    State st;
    if (fitter.run(rng, &st)) {
      const double a = st.poly.area();
      if (a > best_area) best_area = a, r.polygon = st.poly, r.best_start = s;
    }
    if (o.progress) o.progress(s + 1, std::max(1, o.starts));
  }
  if (best_area < 0.0) {
    r.error = "no start produced a feasible polygon";
    return r;
  }
  r.polygon = canonical(r.polygon);
  r.area = r.polygon.area();
  r.ok = true;
  return r;
}

PolygonQuality assessPolygon(const LabelGrid& g, const HalfPlanePolygon& p) {
  PolygonQuality q;
  for (int j = 0; j < g.y.n; ++j) {
    for (int i = 0; i < g.x.n; ++i) {
      const Eigen::Vector2d x = g.node(i, j);
      const bool inside = p.contains(x);
      const std::uint8_t l = g.at(i, j);
      if (l == kCellPreferable) {
        ++q.good_total;
        if (inside) ++q.good_inside;
        else q.r_max = std::max(q.r_max, p.distanceOutside(x));
      } else if (inside) {
        ++q.bad_inside;
        if (l == kCellUnreachable) ++q.unreachable_inside;
      }
    }
  }
  q.coverage = q.good_total > 0 ? static_cast<double>(q.good_inside) / q.good_total : 0.0;
  return q;
}

}  // namespace mft::model
