#pragma once
// Watches a run from the simulator's ground truth: decides when the robot has fallen (base too low, pitch
// too large, a non-foot body on the ground, or a leg at singularity) and keeps the tracking statistics that
// the run summary reports. Pure logic on plain structs: the simulator service and the in-process harness
// use the same criteria.
#include <cmath>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "model/robot_io.hpp"

namespace mft::chain {

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

}  // namespace mft::chain
