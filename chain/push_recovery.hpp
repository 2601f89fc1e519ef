#pragma once
// The one push-recovery criterion of the project (docs/guide/experiments.md, "Recovered"). mft-sim (and through it
// the stack sweep, `mft-experiment case`/`terrain`, scripts) and mft-closedloop both feed a RecoveryWindow
// every control tick and report judgeRecovery()'s verdict in their JSON summaries; nobody re-implements it.
//
// Two outcomes, both always reported:
//   no_fall           no fall (services::RunMonitor's criteria) until the end of the run;
//   back_to_stepping  no fall AND over the last `window_s` of the run the robot steps in place again: |mean base
//                     speed| <= max_speed, |mean base height - mean over the window before the push| <= height_band,
//                     |pitch| <= max_pitch throughout, and at least min_touchdowns touchdowns (still stepping).
// `rule` says which of the two a sweep counts as "recovered".
// Pure logic, no transport; nothing allocates after construction (the window is a fixed ring).
#include <cstdint>
#include <string>
#include <vector>

#include "model/robot_io.hpp"

namespace mft::chain {

enum class RecoveryRule { NoFall, BackToStepping };
const char* toString(RecoveryRule r);
bool parseRecoveryRule(const std::string& text, RecoveryRule* out);  // "no_fall" | "stepping"

struct RecoveryCriteria {
  RecoveryRule rule = RecoveryRule::BackToStepping;
  double window_s = 1.0;        // the final window (and the window before the push)
  double max_speed_mps = 0.05;  // |mean base speed| over the final window
  double height_band_m = 0.02;  // |mean height (final window) - mean height (window before the push)|
  double max_pitch_rad = 0.1;   // |pitch| over the final window
  int min_touchdowns = 2;       // touchdowns of either foot in the final window
  std::string toJson() const;
};

// The base over a window of the run.
struct BaseWindow {
  double from_s = 0, to_s = 0, mean_speed_mps = 0, mean_base_height_m = 0, min_base_height_m = 0,
         max_base_height_m = 0, max_abs_pitch_rad = 0;
  std::uint64_t touchdowns = 0;
  bool empty = true;
  std::string toJson() const;
};

// What a judgement needs from one run.
struct RecoveryRecord {
  double window_s = 1.0;
  int impulses = 0;
  double push_time_s = 0.0, push_impulse_Ns = 0.0;  // the first impulse
  BaseWindow pre, tail;                             // before the first impulse; the end of the run
  double after_min_base_height_m = 0, after_max_abs_pitch_rad = 0, after_max_abs_speed_mps = 0, after_min_lti = 0;
};

enum class RecoveryOutcome { Recovered, Drifting, Fell, NotPushed };
const char* toString(RecoveryOutcome o);

struct RecoveryVerdict {
  bool pushed = false;
  bool no_fall = false;
  bool back_to_stepping = false;
  bool recovered = false;  // under the criteria's rule
  RecoveryOutcome outcome = RecoveryOutcome::NotPushed;  // fell | drifting (no fall, not stepping in place) | recovered
  std::string reason;
  std::string toJson() const;
};

// The judgement. `fell`, `fall_time_s`, `fall_reason` are the RunMonitor's.
RecoveryVerdict judgeRecovery(const RecoveryRecord& record, const RecoveryCriteria& criteria, bool fell,
                              double fall_time_s, const std::string& fall_reason);

// Fed once per control tick with the truth (after the physics step) and the touchdown count of both feet; told
// of each impulse. Keeps the last window_s of the base in a fixed ring buffer.
class RecoveryWindow {
 public:
  RecoveryWindow(double window_s, double control_period_s);

  void update(const model::GroundTruthState& truth, std::uint64_t touchdowns_total);
  // The first impulse snapshots the window before it; later ones are only counted.
  void onImpulse(double time_s, double impulse_x_Ns);

  RecoveryRecord record() const;
  // {"window_s", "impulses", "push_time_s", "push_impulse_Ns", "pre", "after", "tail", "criteria", "verdict"}
  std::string json(const RecoveryCriteria& criteria, bool fell, double fall_time_s, const std::string& fall_reason) const;

 private:
  struct Sample {
    double t, x, z, pitch;
    std::uint64_t touchdowns;
  };
  BaseWindow summarize() const;
  const Sample& at(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }

  double window_s_;
  std::vector<Sample> ring_;
  std::size_t head_ = 0, size_ = 0;
  bool pushed_ = false;
  int impulses_ = 0;
  double push_time_s_ = 0, push_Ns_ = 0;
  BaseWindow pre_;
  double after_min_z_, after_max_pitch_ = 0, after_max_speed_ = 0, after_min_lti_;
};

}  // namespace mft::chain
