#include "qp_commands.hpp"

#include <malloc.h>
#include <sched.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <vector>

#include "common/tool_io.hpp"
#include "wbc/qp/qp_io.hpp"
#include "wbc/qp/qp_kkt.hpp"
#include "wbc/qp/qp_solver.hpp"

namespace mft::tools {
namespace {

using qp::QpInstance;
using qp::QpSolution;
using qp::QpStatus;

struct Accuracy {
  double x_err = 0.0;   // max |x - x_ref| (NaN-safe: a non-finite difference counts as +inf)
  double kkt = 0.0;     // max KKT residual
  int mismatched = 0;   // entries differing from active_ref
  int strict_mismatched = 0;  // of which a side claimed active is not tight at our x
};

Accuracy checkSolution(const QpInstance& inst, const QpSolution& s) {
  Accuracy a;
  const qp::QpProblem& p = inst.problem;
  if (inst.x_ref) {
    for (int j = 0; j < p.n; ++j) {
      const double e = std::abs(s.x[j] - (*inst.x_ref)[j]);
      a.x_err = std::isnan(e) ? qp::kInf : std::max(a.x_err, e);
    }
  }
  a.kkt = qp::kktResiduals(p, s).max();
  if (inst.active_ref) {
    const Eigen::VectorXd rows = p.Ain * s.x;
    for (int i = 0; i < p.n + p.nin; ++i) {
      const int ours = s.active[i], ref = (*inst.active_ref)[i];
      if (ours == ref) continue;
      ++a.mismatched;
      const bool bound = i < p.n;
      const int k = bound ? i : i - p.n;
      const double v = bound ? s.x[k] : rows[k];
      const double lo = bound ? p.lb[k] : p.lbA[k], hi = bound ? p.ub[k] : p.ubA[k];
      // With x matching, a differing entry is a tie (zero multiplier) or a dependent tight set (non-unique
      // multipliers) as long as every side claimed active by either set is tight at our x.
      const double tight_tol = 1e-7 * (1.0 + std::abs(v));
      auto tight = [&](int side) { return side == 0 || (side < 0 ? std::abs(v - lo) : std::abs(hi - v)) <= tight_tol; };
      if (!tight(ours) || !tight(ref)) ++a.strict_mismatched;
    }
  }
  return a;
}

// The run of an instance named <run>_<tick> (docs/reference/qp-instances.md): the name without its last "_<suffix>".
std::string runName(const std::string& name) { return name.substr(0, name.rfind('_')); }

// The solver's "optimal" is reported only when its answer satisfies the KKT conditions (stationarity,
// primal and dual feasibility, complementarity) within kKktTolerance relative to the data's scale, with a
// finite x and objective; otherwise the answer is "unverified" and `why` says which condition failed. (An
// asymmetric H or an overflowing g once came back "optimal" with a stationarity residual of 5 or a NaN
// objective.)
constexpr double kKktTolerance = 1e-6;
bool verifiedOptimal(const qp::QpProblem& p, const QpSolution& s, const qp::KktResiduals& k, std::string* why) {
  auto inf = [](const auto& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; };
  char buf[200];
  if (!s.x.allFinite() || !std::isfinite(s.objective)) {
    *why = "x or the objective is not finite";
    return false;
  }
  const double x_scale = 1.0 + inf(s.x);
  const double y_scale = 1.0 + std::max({inf(s.y_eq), inf(s.y_bounds), inf(s.y_rows)});
  const Eigen::VectorXd hx = p.H * s.x;
  const struct {
    const char* name;
    double residual, scale;
  } checks[] = {{"stationarity", k.stationarity, 1.0 + std::max(inf(hx), inf(p.g))},
                {"primal feasibility", k.primal, x_scale + inf(p.Aeq * s.x) + inf(p.Ain * s.x)},
                {"dual feasibility", k.dual, y_scale},
                {"complementarity", k.complementarity, y_scale * x_scale}};
  for (const auto& c : checks)
    if (!(c.residual <= kKktTolerance * c.scale)) {
      std::snprintf(buf, sizeof buf, "%s residual %.3g > %.0e x scale %.3g", c.name, c.residual, kKktTolerance, c.scale);
      *why = buf;
      return false;
    }
  return true;
}

std::vector<QpInstance> loadFolder(const std::string& dir) {
  const std::vector<std::string> files = qp::listQpInstanceFiles(dir);
  if (files.empty()) throw qp::QpIoError(dir + ": no *.txt instances");
  std::vector<QpInstance> out;
  out.reserve(files.size());
  for (const std::string& f : files) out.push_back(qp::readQpInstance(f));
  return out;
}

// Real-time hygiene as in docs/reference/qp.md#measuring-solve-time; every step degrades gracefully and is reported.
std::string prepareProcess(int cpu) {
  std::string notes;
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0)
    notes += "mlockall ok";
  else
    notes += std::string("mlockall unavailable (") + std::strerror(errno) + ")";
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) == 0)
      notes += "; pinned to cpu " + std::to_string(cpu);
    else
      notes += "; pinning to cpu " + std::to_string(cpu) + " failed (" + std::strerror(errno) + ")";
  } else {
    notes += "; not pinned";
  }
  return notes;
}

double percentile(const std::vector<double>& sorted, double p) {
  const std::size_t i = std::min(sorted.size() - 1, static_cast<std::size_t>(p * static_cast<double>(sorted.size())));
  return sorted[i];
}

// Residuals and timings at 6 significant digits; an infinite residual as +-1e308 (a number, so that a
// comparison in a script still works), NaN as null.
constexpr int kDigits = 6;
double clampInfinite(double v) { return std::isinf(v) ? (v > 0 ? 1e308 : -1e308) : v; }
// Solution values at full precision (they round-trip like the instance files).
constexpr int kExact = 17;

// What a bench pass adds up: the accuracy of the last pass, the times of every pass.
struct BenchTally {
  std::vector<double> best;  // per instance: the fastest solve over the passes [us]
  double raw_max = 0.0;
  int failures = 0, fallbacks = 0;
  long long iterations_sum = 0;
  int iterations_max = 0;
  Accuracy worst;
  int steps_mismatched = 0, steps_strict = 0;
};

// The last pass's verdict on one solve: optimal and verified, then its accuracy against the reference.
void judgeSolve(const BenchOptions& o, const QpInstance& inst, QpStatus st, const QpSolution& sol, BenchTally* t) {
  std::string why;
  if (st != QpStatus::Optimal) {
    ++t->failures;
    if (!o.json) std::cerr << inst.name << ": " << qp::toString(st) << "\n";
    return;
  }
  if (!verifiedOptimal(inst.problem, sol, qp::kktResiduals(inst.problem, sol), &why)) {
    ++t->failures;
    if (!o.json) std::cerr << inst.name << ": unverified: " << why << "\n";
    return;
  }
  const Accuracy a = checkSolution(inst, sol);
  t->worst.x_err = std::max(t->worst.x_err, a.x_err);
  t->worst.kkt = std::max(t->worst.kkt, a.kkt);
  t->worst.mismatched += a.mismatched;
  t->worst.strict_mismatched += a.strict_mismatched;
  t->steps_mismatched += a.mismatched ? 1 : 0;
  t->steps_strict += a.strict_mismatched ? 1 : 0;
}

// One pass over every instance with a fresh solver (no warm-start state carried from the previous pass).
void benchPass(const BenchOptions& o, const std::vector<QpInstance>& instances, bool last, BenchTally* t) {
  const qp::QpProblem& first = instances.front().problem;
  qp::GoldfarbIdnaniSolver solver(first.n, first.neq, first.nin);
  solver.options().warm_start = o.warm;
  QpSolution sol;
  sol.resize(first.n, first.neq, first.nin);
  for (std::size_t k = 0; k < instances.size(); ++k) {
    // Instances named <run>_<tick> form runs of consecutive ticks: a new run starts without warm-start state.
    if (k > 0 && runName(instances[k].name) != runName(instances[k - 1].name)) solver.clearWarmStart();
    const auto t0 = std::chrono::steady_clock::now();
    const QpStatus st = solver.solve(instances[k].problem, &sol);
    const auto t1 = std::chrono::steady_clock::now();
    const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
    t->best[k] = std::min(t->best[k], us);
    t->raw_max = std::max(t->raw_max, us);
    if (!last) continue;
    // Accuracy from the last pass (every pass solves the same problems the same way).
    t->fallbacks += solver.lastSolveFellBack() ? 1 : 0;
    t->iterations_sum += sol.iterations;
    t->iterations_max = std::max(t->iterations_max, sol.iterations);
    judgeSolve(o, instances[k], st, sol, t);
  }
}

}  // namespace

int runBench(const BenchOptions& o) {
  const std::vector<QpInstance> instances = loadFolder(o.dir);
  const std::string notes = prepareProcess(o.cpu);
  const std::size_t count = instances.size();
  BenchTally t;
  t.best.assign(count, qp::kInf);
  for (int pass = 0; pass < o.passes; ++pass) benchPass(o, instances, pass == o.passes - 1, &t);
  std::vector<double> sorted = t.best;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0;
  for (double v : sorted) sum += v;
  const double mean = sum / static_cast<double>(count);
  const double iter_mean = static_cast<double>(t.iterations_sum) / static_cast<double>(count);
  const Accuracy& worst = t.worst;
  const double raw_max = t.raw_max;
  const int failures = t.failures, fallbacks = t.fallbacks, iterations_max = t.iterations_max;
  const int steps_mismatched = t.steps_mismatched, steps_strict = t.steps_strict;

  if (o.json) {
    config::JsonWriter w;
    w.beginObject().field("dir", o.dir).field("count", count).field("passes", o.passes).field("warm", o.warm);
    w.field("failures", failures).field("warm_fallbacks", fallbacks).field("max_x_err", clampInfinite(worst.x_err), kDigits);
    w.field("max_kkt", clampInfinite(worst.kkt), kDigits).field("active_mismatch_steps", steps_mismatched);
    w.field("active_mismatch_steps_nondegenerate", steps_strict).field("iterations_mean", iter_mean, kDigits);
    w.field("iterations_max", iterations_max).field("mean_us", mean, kDigits);
    w.field("p50_us", percentile(sorted, 0.5), kDigits).field("p99_us", percentile(sorted, 0.99), kDigits);
    w.field("max_us", sorted.back(), kDigits).field("raw_max_us", raw_max, kDigits).field("process", notes);
    std::cout << w.endObject().str() << "\n";
  } else {
    std::printf("instances            %zu (%s)\n", count, o.dir.c_str());
    std::printf("mode                 %s, %d passes, per-step minimum over passes (%s)\n", o.warm ? "warm" : "cold",
                o.passes, notes.c_str());
    std::printf("failures             %d%s\n", failures, o.warm ? (" (warm fallbacks " + std::to_string(fallbacks) + ")").c_str() : "");
    std::printf("max |x - x_ref|      %.3g\n", worst.x_err);
    std::printf("max KKT residual     %.3g\n", worst.kkt);
    std::printf("active-set mismatch  %d steps (%d entries); not explained by degeneracy: %d steps\n", steps_mismatched,
                worst.mismatched, steps_strict);
    std::printf("iterations           mean %.2f, max %d\n", iter_mean, iterations_max);
    std::printf("solve time [us]      mean %.2f  p50 %.2f  p99 %.2f  max %.2f  (raw max %.2f)\n", mean,
                percentile(sorted, 0.5), percentile(sorted, 0.99), sorted.back(), raw_max);
  }
  return failures ? 1 : 0;
}

int runSolve(const SolveOptions& o) {
  const QpInstance inst = qp::readQpInstance(o.file);
  const qp::QpProblem& p = inst.problem;
  qp::GoldfarbIdnaniSolver solver(p.n, p.neq, p.nin);
  QpSolution sol;
  sol.resize(p.n, p.neq, p.nin);
  const auto t0 = std::chrono::steady_clock::now();
  const QpStatus st = solver.solve(p, &sol);
  const auto t1 = std::chrono::steady_clock::now();
  const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
  const qp::KktResiduals kkt = qp::kktResiduals(p, sol);
  const Accuracy a = checkSolution(inst, sol);
  std::string why;
  const bool optimal = st == QpStatus::Optimal && verifiedOptimal(p, sol, kkt, &why);
  // "unverified": the solver claimed optimal but its answer fails the KKT check.
  const std::string status = st == QpStatus::Optimal && !optimal ? "unverified" : qp::toString(st);
  std::ostringstream active;
  for (int i = 0; i < p.n + p.nin; ++i)
    if (sol.active[i]) active << (active.tellp() ? " " : "") << (i < p.n ? "x" : "row") << (i < p.n ? i : i - p.n) << (sol.active[i] > 0 ? "+" : "-");
  if (o.json) {
    config::JsonWriter w;
    w.beginObject().field("file", o.file).field("name", inst.name).field("status", status).key("unverified_because");
    if (why.empty()) w.null();
    else w.value(why);
    w.field("iterations", sol.iterations).field("objective", clampInfinite(sol.objective), kExact).key("f_ref");
    if (inst.f_ref) w.value(clampInfinite(*inst.f_ref), kExact);
    else w.null();
    w.key("max_x_err");
    if (inst.x_ref) w.value(clampInfinite(a.x_err), kDigits);
    else w.null();
    w.key("kkt").beginObject().field("stationarity", clampInfinite(kkt.stationarity), kDigits);
    w.field("primal", clampInfinite(kkt.primal), kDigits).field("dual", clampInfinite(kkt.dual), kDigits);
    w.field("complementarity", clampInfinite(kkt.complementarity), kDigits).endObject().key("active_mismatch");
    if (inst.active_ref) w.value(a.mismatched);
    else w.null();
    w.field("active", active.str()).field("solve_us", us, kDigits).key("x").beginArray();
    for (int j = 0; j < p.n; ++j) w.value(clampInfinite(sol.x[j]), kExact);
    std::cout << w.endArray().endObject().str() << "\n";
  } else {
    std::printf("instance        %s (%s)\n", inst.name.c_str(), o.file.c_str());
    std::printf("status          %s, %d iterations, %.2f us (single cold call)\n", status.c_str(), sol.iterations, us);
    if (!why.empty()) std::printf("not optimal     the solver said optimal, but %s\n", why.c_str());
    std::printf("objective       %.17g", sol.objective);
    if (inst.f_ref) std::printf("  (f_ref %.17g)", *inst.f_ref);
    std::printf("\n");
    if (inst.x_ref) std::printf("max |x - x_ref| %.3g\n", a.x_err);
    std::printf("KKT             stationarity %.3g  primal %.3g  dual %.3g  complementarity %.3g\n", kkt.stationarity,
                kkt.primal, kkt.dual, kkt.complementarity);
    std::printf("active          %s\n", active.str().c_str());
    if (inst.active_ref) std::printf("vs active_ref   %d entries differ (%d not explained by degeneracy)\n", a.mismatched, a.strict_mismatched);
  }
  return optimal ? 0 : 1;
}

}  // namespace mft::tools
