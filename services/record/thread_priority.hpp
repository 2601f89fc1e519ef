#pragma once
// Recording must not slow the stack. Once every 1 kHz topic flows (discovery done at full priority, so the first
// ticks are not missed), the recorder's DDS threads go to the background and the stack gets the CPU first; the
// recorder catches up from its socket buffers. The writer thread and the main thread keep their priority (the
// writer's queue is not covered by the lockstep window). Linux: nice and the policy are per thread.
#include <cstdint>
#include <string>

#include "common/json_writer.hpp"
#include "services/record/recorder.hpp"

namespace mft::services {

enum class Background { kNone, kNice, kIdle };

// --background: auto (lockstep idle, realtime nice), idle, nice or none; false for another word.
bool parseBackground(const std::string& text, bool lockstep, Background* out);

class BackgroundPolicy {
 public:
  // `scenario_end_ns`: the stamp of the scenario's end; `polling`: the receive path is polled (--poll-us > 0).
  BackgroundPolicy(Background how, long nice_value, double scenario_duration_s, bool polling);
  // Every loop of the main thread (5 ms).
  void update(const rawlog::Recorder& recorder, bool topics_flowing);
  // Back to full priority (to drain the socket buffers at the end).
  void restore(const rawlog::Recorder& recorder);
  int starvationFallbacks() const { return starvation_fallbacks_; }

 private:
  Background how_;
  long nice_;
  std::uint64_t end_ns_;
  bool polling_, reniced_, near_end_ = false;
  int starvation_fallbacks_ = 0;
};

// CPU seconds used so far by this process's threads, summed by thread name (the DDS receive threads versus the
// writer): what the recorder costs the machine, independent of how busy the machine is.
std::string threadCpuJson();
// What the polling receive path did (all zero with --poll-us 0), and the starvation fallbacks: fields of the
// summary being written.
void writePollFields(config::JsonWriter& w, int starvation_fallbacks);

}  // namespace mft::services
