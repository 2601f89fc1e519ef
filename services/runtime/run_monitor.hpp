#pragma once
// Watches a run from the simulator's ground truth: decides when the robot has fallen (base too low, pitch
// too large, a non-foot body on the ground, or a leg at singularity) and keeps the tracking statistics that
// the run summary reports. Pure logic on plain structs: the simulator service and the in-process harness
// use the same criteria.
#include <cmath>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <limits>
#include <string>

#include "model/robot_io.hpp"

namespace mft::services {

struct FallCriteria {
  double base_height_below_m = 0.25;
  double pitch_beyond_rad = 0.8;
  double lti_below = 0.02;          // a leg this close to a singular configuration
  bool body_contact_is_fall = true; // a thigh, shank or the torso touching the ground
};

struct ErrorStats {
  double sum_sq = 0.0, max_abs = 0.0;
  std::uint64_t n = 0;
  void add(double e) {
    sum_sq += e * e;
    max_abs = std::max(max_abs, std::abs(e));
    ++n;
  }
  double rms() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }
};

class RunMonitor {
 public:
  RunMonitor(FallCriteria criteria, double settle_time_s) : criteria_(criteria), settle_time_s_(settle_time_s) {}

  // Called once per control tick with the truth, the commanded base height and the simulator's count of
  // physics steps with a non-foot body on the ground. Returns true when the robot has fallen (first time).
  bool update(const model::GroundTruthState& truth, double z_cmd, std::uint64_t body_contact_steps) {
    if (!have_start_) {
      start_x_ = truth.q[0];
      have_start_ = true;
    }
    last_x_ = truth.q[0];
    last_time_s_ = truth.time_s;
    if (truth.time_s >= settle_time_s_) {
      height_.add(truth.q[1] - z_cmd);
      pitch_.add(truth.q[2]);
    }
    if (fell_) return false;
    std::string why;
    if (truth.q[1] < criteria_.base_height_below_m) why = "base below " + std::to_string(criteria_.base_height_below_m) + " m";
    else if (std::abs(truth.q[2]) > criteria_.pitch_beyond_rad) why = "pitch beyond " + std::to_string(criteria_.pitch_beyond_rad) + " rad";
    else if (criteria_.body_contact_is_fall && body_contact_steps > 0) why = "a non-foot body touched the ground";
    else if (std::min(truth.lti[0], truth.lti[1]) < criteria_.lti_below) why = "a leg reached a singular configuration";
    else if (!truth.q.allFinite()) why = "the state is not finite";
    if (why.empty()) return false;
    fell_ = true;
    fall_time_s_ = truth.time_s;
    fall_reason_ = why;
    return true;
  }

  bool fell() const { return fell_; }
  double fallTime() const { return fall_time_s_; }
  const std::string& fallReason() const { return fall_reason_; }
  const ErrorStats& heightError() const { return height_; }
  const ErrorStats& pitchError() const { return pitch_; }
  double distance() const { return last_x_ - start_x_; }
  double averageSpeed() const { return last_time_s_ > 0 ? distance() / last_time_s_ : 0.0; }

 private:
  FallCriteria criteria_;
  double settle_time_s_;
  bool fell_ = false, have_start_ = false;
  double fall_time_s_ = 0.0, start_x_ = 0.0, last_x_ = 0.0, last_time_s_ = 0.0;
  std::string fall_reason_;
  ErrorStats height_, pitch_;
};

// What a push-recovery judgement needs from one run (tools/mft-experiment): the base over the window before
// the first impulse, the extremes after it, and the base over the last window of the run (is the robot back
// to stepping in place?). Fed once per control tick with the truth and the touchdown count of both feet.
class RecoveryWindow {
 public:
  explicit RecoveryWindow(double window_s = 1.0) : window_s_(window_s) {}

  void update(const model::GroundTruthState& truth, std::uint64_t touchdowns_total) {
    samples_.push_back({truth.time_s, truth.q[0], truth.q[1], truth.q[2], truth.qd[0], touchdowns_total});
    while (!samples_.empty() && samples_.front().t < truth.time_s - window_s_ - 1e-9) samples_.pop_front();
    if (pushed_) {
      after_min_z_ = std::min(after_min_z_, truth.q[1]);
      after_max_pitch_ = std::max(after_max_pitch_, std::abs(truth.q[2]));
      after_max_speed_ = std::max(after_max_speed_, std::abs(truth.qd[0]));
      after_min_lti_ = std::min(after_min_lti_, std::min(truth.lti[0], truth.lti[1]));
    }
  }

  // The first impulse (later ones are counted only): snapshot the window before it.
  void onImpulse(double time_s, double impulse_x_Ns) {
    ++impulses_;
    if (pushed_) return;
    pushed_ = true;
    push_time_s_ = time_s;
    push_Ns_ = impulse_x_Ns;
    pre_ = summarize();
  }

  std::string json() const {
    const Window tail = summarize();
    char buf[1200];
    std::snprintf(buf, sizeof buf,
                  "{\"window_s\": %.3f, \"impulses\": %d, \"push_time_s\": %s, \"push_impulse_Ns\": %.4f, "
                  "\"pre\": %s, \"after\": {\"min_base_height_m\": %s, \"max_abs_pitch_rad\": %s, "
                  "\"max_abs_speed_mps\": %s, \"min_lti\": %s}, \"tail\": %s}",
                  window_s_, impulses_, pushed_ ? num(push_time_s_).c_str() : "null", push_Ns_,
                  pushed_ ? pre_.json().c_str() : "null", pushed_ ? num(after_min_z_).c_str() : "null",
                  pushed_ ? num(after_max_pitch_).c_str() : "null", pushed_ ? num(after_max_speed_).c_str() : "null",
                  pushed_ ? num(after_min_lti_).c_str() : "null", tail.json().c_str());
    return buf;
  }

 private:
  struct Sample {
    double t, x, z, pitch, xd;
    std::uint64_t touchdowns;
  };
  struct Window {
    double from_s = 0, to_s = 0, mean_speed = 0, mean_z = 0, min_z = 0, max_z = 0, max_pitch = 0;
    std::uint64_t touchdowns = 0;
    std::string json() const {
      char b[400];
      std::snprintf(b, sizeof b,
                    "{\"from_s\": %.4f, \"to_s\": %.4f, \"mean_speed_mps\": %.5f, \"mean_base_height_m\": %.5f, "
                    "\"min_base_height_m\": %.5f, \"max_base_height_m\": %.5f, \"max_abs_pitch_rad\": %.5f, "
                    "\"touchdowns\": %llu}",
                    from_s, to_s, mean_speed, mean_z, min_z, max_z, max_pitch, static_cast<unsigned long long>(touchdowns));
      return b;
    }
  };
  static std::string num(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.5f", v);
    return b;
  }
  Window summarize() const {
    Window w;
    if (samples_.empty()) return w;
    const auto& a = samples_.front();
    const auto& e = samples_.back();
    w.from_s = a.t;
    w.to_s = e.t;
    w.mean_speed = e.t > a.t ? (e.x - a.x) / (e.t - a.t) : 0.0;
    w.min_z = std::numeric_limits<double>::infinity();
    w.max_z = -w.min_z;
    double sum = 0;
    for (const auto& s : samples_) {
      sum += s.z;
      w.min_z = std::min(w.min_z, s.z);
      w.max_z = std::max(w.max_z, s.z);
      w.max_pitch = std::max(w.max_pitch, std::abs(s.pitch));
    }
    w.mean_z = sum / static_cast<double>(samples_.size());
    w.touchdowns = e.touchdowns - a.touchdowns;
    return w;
  }

  double window_s_;
  std::deque<Sample> samples_;
  bool pushed_ = false;
  int impulses_ = 0;
  double push_time_s_ = 0, push_Ns_ = 0;
  Window pre_;
  double after_min_z_ = std::numeric_limits<double>::infinity(), after_max_pitch_ = 0, after_max_speed_ = 0,
         after_min_lti_ = std::numeric_limits<double>::infinity();
};

}  // namespace mft::services
