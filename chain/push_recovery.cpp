#include "chain/push_recovery.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "common/json_writer.hpp"

namespace mft::chain {
namespace {

constexpr int kDecimals = 5;  // the summaries' default for metres, radians and speeds

}  // namespace

const char* toString(RecoveryRule r) { return r == RecoveryRule::NoFall ? "no_fall" : "stepping"; }

bool parseRecoveryRule(const std::string& text, RecoveryRule* out) {
  if (text == "no_fall") *out = RecoveryRule::NoFall;
  else if (text == "stepping") *out = RecoveryRule::BackToStepping;
  else return false;
  return true;
}

const char* toString(RecoveryOutcome o) {
  switch (o) {
    case RecoveryOutcome::Recovered: return "recovered";
    case RecoveryOutcome::Drifting: return "drifting";
    case RecoveryOutcome::Fell: return "fell";
    case RecoveryOutcome::NotPushed: return "not_pushed";
  }
  return "?";
}

std::string RecoveryCriteria::toJson() const {
  config::JsonWriter w;
  w.beginObject().field("rule", toString(rule)).fixedField("window_s", window_s, 3);
  w.fixedField("max_speed_mps", max_speed_mps, 4).fixedField("height_band_m", height_band_m, 4);
  w.fixedField("max_pitch_rad", max_pitch_rad, 4).field("min_touchdowns", min_touchdowns);
  return w.endObject().str();
}

std::string BaseWindow::toJson() const {
  if (empty) return "null";
  config::JsonWriter w;
  w.beginObject().fixedField("from_s", from_s, 4).fixedField("to_s", to_s, 4);
  w.fixedField("mean_speed_mps", mean_speed_mps, kDecimals).fixedField("mean_base_height_m", mean_base_height_m, kDecimals);
  w.fixedField("min_base_height_m", min_base_height_m, kDecimals).fixedField("max_base_height_m", max_base_height_m, kDecimals);
  w.fixedField("max_abs_pitch_rad", max_abs_pitch_rad, kDecimals).field("touchdowns", touchdowns);
  return w.endObject().str();
}

std::string RecoveryVerdict::toJson() const {
  config::JsonWriter w;
  w.beginObject().field("recovered", recovered).field("outcome", toString(outcome)).field("pushed", pushed);
  w.field("no_fall", no_fall).field("back_to_stepping", back_to_stepping).field("reason", reason);
  return w.endObject().str();
}

RecoveryVerdict judgeRecovery(const RecoveryRecord& r, const RecoveryCriteria& c, bool fell, double fall_time_s,
                              const std::string& fall_reason) {
  RecoveryVerdict v;
  v.pushed = r.impulses > 0;
  v.no_fall = !fell;
  char b[200];
  if (fell) {
    std::snprintf(b, sizeof b, "fell at %.3f s: ", fall_time_s);
    v.outcome = RecoveryOutcome::Fell;
    v.reason = b + fall_reason;
  } else if (!v.pushed) {
    v.outcome = RecoveryOutcome::NotPushed;
    v.reason = "no push was applied";
  } else if (r.tail.empty || r.pre.empty || r.tail.from_s < r.push_time_s) {
    // The final window must lie wholly after the push, else "back to stepping" says nothing about the push.
    v.outcome = RecoveryOutcome::Drifting;
    v.reason = "the run ended less than one window after the push";
  } else {
    std::string why;
    auto add = [&why](const std::string& s) { why += (why.empty() ? "" : "; ") + s; };
    if (std::abs(r.tail.mean_speed_mps) > c.max_speed_mps) {
      std::snprintf(b, sizeof b, "|mean speed| %.3f > %g m/s", std::abs(r.tail.mean_speed_mps), c.max_speed_mps);
      add(b);
    }
    const double dz = r.tail.mean_base_height_m - r.pre.mean_base_height_m;
    if (std::abs(dz) > c.height_band_m) {
      std::snprintf(b, sizeof b, "base height %+.1f mm from before the push (band %g mm)", dz * 1e3,
                    c.height_band_m * 1e3);
      add(b);
    }
    if (r.tail.max_abs_pitch_rad > c.max_pitch_rad) {
      std::snprintf(b, sizeof b, "|pitch| %.3f > %g rad", r.tail.max_abs_pitch_rad, c.max_pitch_rad);
      add(b);
    }
    if (r.tail.touchdowns < static_cast<std::uint64_t>(std::max(0, c.min_touchdowns))) {
      std::snprintf(b, sizeof b, "%llu touchdowns in the last %g s (not stepping)",
                    static_cast<unsigned long long>(r.tail.touchdowns), c.window_s);
      add(b);
    }
    v.back_to_stepping = why.empty();
    v.outcome = v.back_to_stepping ? RecoveryOutcome::Recovered : RecoveryOutcome::Drifting;
    v.reason = v.back_to_stepping ? "back to stepping in place" : "no fall but not stepping in place: " + why;
  }
  v.recovered = v.pushed && (c.rule == RecoveryRule::NoFall ? v.no_fall : v.back_to_stepping);
  if (v.recovered && c.rule == RecoveryRule::NoFall && !v.back_to_stepping) v.reason = "no fall (" + v.reason + ")";
  return v;
}

RecoveryWindow::RecoveryWindow(double window_s, double control_period_s)
    : window_s_(window_s),
      after_min_z_(std::numeric_limits<double>::infinity()),
      after_min_lti_(std::numeric_limits<double>::infinity()) {
  if (!(window_s > 0.0) || !(control_period_s > 0.0))
    throw std::invalid_argument("RecoveryWindow: the window and the control period must be positive");
  ring_.resize(static_cast<std::size_t>(std::ceil(window_s / control_period_s)) + 3);
}

void RecoveryWindow::update(const model::GroundTruthState& truth, std::uint64_t touchdowns_total) {
  const Sample s{truth.time_s, truth.q[0], truth.q[1], truth.q[2], touchdowns_total};
  if (size_ == ring_.size()) {  // full: drop the oldest (the ring is sized for the window at the control period)
    head_ = (head_ + 1) % ring_.size();
    --size_;
  }
  ring_[(head_ + size_) % ring_.size()] = s;
  ++size_;
  while (size_ > 0 && at(0).t < truth.time_s - window_s_ - 1e-9) {
    head_ = (head_ + 1) % ring_.size();
    --size_;
  }
  if (pushed_) {
    after_min_z_ = std::min(after_min_z_, truth.q[1]);
    after_max_pitch_ = std::max(after_max_pitch_, std::abs(truth.q[2]));
    after_max_speed_ = std::max(after_max_speed_, std::abs(truth.qd[0]));
    after_min_lti_ = std::min(after_min_lti_, std::min(truth.lti[0], truth.lti[1]));
  }
}

void RecoveryWindow::onImpulse(double time_s, double impulse_x_Ns) {
  ++impulses_;
  if (pushed_) return;
  pushed_ = true;
  push_time_s_ = time_s;
  push_Ns_ = impulse_x_Ns;
  pre_ = summarize();
}

BaseWindow RecoveryWindow::summarize() const {
  BaseWindow w;
  if (size_ == 0) return w;
  const Sample& a = at(0);
  const Sample& e = at(size_ - 1);
  w.empty = false;
  w.from_s = a.t;
  w.to_s = e.t;
  w.mean_speed_mps = e.t > a.t ? (e.x - a.x) / (e.t - a.t) : 0.0;
  w.min_base_height_m = std::numeric_limits<double>::infinity();
  w.max_base_height_m = -w.min_base_height_m;
  double sum = 0;
  for (std::size_t i = 0; i < size_; ++i) {
    const Sample& s = at(i);
    sum += s.z;
    w.min_base_height_m = std::min(w.min_base_height_m, s.z);
    w.max_base_height_m = std::max(w.max_base_height_m, s.z);
    w.max_abs_pitch_rad = std::max(w.max_abs_pitch_rad, std::abs(s.pitch));
  }
  w.mean_base_height_m = sum / static_cast<double>(size_);
  w.touchdowns = e.touchdowns - a.touchdowns;
  return w;
}

RecoveryRecord RecoveryWindow::record() const {
  RecoveryRecord r;
  r.window_s = window_s_;
  r.impulses = impulses_;
  r.push_time_s = push_time_s_;
  r.push_impulse_Ns = push_Ns_;
  r.pre = pre_;
  r.tail = summarize();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.after_min_base_height_m = pushed_ ? after_min_z_ : nan;
  r.after_max_abs_pitch_rad = pushed_ ? after_max_pitch_ : nan;
  r.after_max_abs_speed_mps = pushed_ ? after_max_speed_ : nan;
  r.after_min_lti = pushed_ ? after_min_lti_ : nan;
  return r;
}

std::string RecoveryWindow::json(const RecoveryCriteria& criteria, bool fell, double fall_time_s,
                                 const std::string& fall_reason) const {
  const RecoveryRecord r = record();
  const RecoveryVerdict v = judgeRecovery(r, criteria, fell, fall_time_s, fall_reason);
  const bool p = r.impulses > 0;
  config::JsonWriter w;
  w.beginObject().fixedField("window_s", r.window_s, 3).field("impulses", r.impulses).key("push_time_s");
  if (p) w.fixed(r.push_time_s, kDecimals);
  else w.null();
  w.fixedField("push_impulse_Ns", r.push_impulse_Ns, 4).key("pre").raw(p ? r.pre.toJson() : "null").key("after");
  if (p) {
    w.beginObject().fixedField("min_base_height_m", r.after_min_base_height_m, kDecimals);
    w.fixedField("max_abs_pitch_rad", r.after_max_abs_pitch_rad, kDecimals);
    w.fixedField("max_abs_speed_mps", r.after_max_abs_speed_mps, kDecimals);
    w.fixedField("min_lti", r.after_min_lti, kDecimals).endObject();
  } else {
    w.null();
  }
  w.key("tail").raw(r.tail.toJson()).key("criteria").raw(criteria.toJson()).key("verdict").raw(v.toJson());
  return w.endObject().str();
}

}  // namespace mft::chain
