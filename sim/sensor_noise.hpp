#pragma once
// Seeded Gaussian sensor noise and fixed IMU biases, applied to clean readings. Same seed -> same noise.
#include "model/robot_io.hpp"
#include "sim/random.hpp"
#include "sim/sim_options.hpp"

namespace mft::sim {

class SensorNoise {
 public:
  explicit SensorNoise(const NoiseOptions& options) : options_(options), rng_(options.seed) {}
  void reseed() { rng_ = SplitMix64(options_.seed); }
  void apply(model::SensorReadings* s);

 private:
  NoiseOptions options_;
  SplitMix64 rng_;
};

}  // namespace mft::sim
