#include "sim/sensor_noise.hpp"

namespace mft::sim {

void SensorNoise::apply(model::SensorReadings* s) {
  if (!options_.enabled) return;
  const NoiseOptions& o = options_;
  for (int i = 0; i < model::kNa; ++i) {
    s->actuated_pos[i] += o.encoder_position_std_rad * rng_.gaussian();
    s->actuated_vel[i] += o.encoder_velocity_std_radps * rng_.gaussian();
    s->passive_pos[i] += o.encoder_position_std_rad * rng_.gaussian();
    s->passive_vel[i] += o.encoder_velocity_std_radps * rng_.gaussian();
    s->sea_torque[i] += o.sea_torque_std_Nm * rng_.gaussian();
  }
  s->gyro_pitch_rate += o.gyro_bias_radps + o.gyro_std_radps * rng_.gaussian();
  for (int i = 0; i < 2; ++i) s->accel[i] += o.accel_bias_mps2[i] + o.accel_std_mps2 * rng_.gaussian();
}

}  // namespace mft::sim
