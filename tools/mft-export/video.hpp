#pragma once
// mft-export FILE --video OUT.mp4|OUT.gif: a run video. This side reads the rawlog(s) as a stream, samples the
// ground truth at each video frame's simulated time, computes every drawn point with the project's own
// kinematics (robot_drawing.hpp) and hands one JSON line per frame to the renderer (mft-video.py:
// matplotlib, piped into ffmpeg). Nothing is kept per frame on either side. docs/guide/videos.md.
#include <string>

#include "services/runtime/process.hpp"

namespace mft::video {

// The --video mode of mft-export; returns the exit status (0, 2 bad input / I/O, 4 corrupt, 130 interrupted).
int videoMain(const services::CommandLine& cli, const std::string& file);

}  // namespace mft::video
