#pragma once
// Estimator parameters, loaded strictly from config/estimator.yaml (units in the key names there).
#include <string>

namespace mft::estimator {

enum class EstimatorMode { Kalman, GroundTruth };
enum class ContactSource { Switch, Force, Either, Both };

struct KalmanParams {
  double accel_noise_density = 0.5;        // accelerometer white noise [m/s^2/sqrt(Hz)] (process noise of v)
  double foot_slip_density = 0.01;         // random walk of a stance foot [m/sqrt(s)]
  double kinematic_position_std_m = 0.003; // foot-relative-to-base measurement noise (encoders, link lengths)
  double kinematic_velocity_std_mps = 0.03;
  bool use_ground_height = true;           // pseudo-measurement: a stance foot is at ground_height_m
  double ground_height_m = 0.0;
  double ground_height_std_m = 0.02;
  double initial_position_std_m = 0.01;
  double initial_velocity_std_mps = 0.1;
};

struct PitchParams {
  double correction_time_constant_s = 1.0;  // accelerometer tilt correction: pitch error decays with this
  double gyro_bias_gain = 0.25;             // integral gain of the bias estimate [1/s^2], 0 = no bias estimate
  double accel_gate_mps2 = 2.0;             // tilt used only when the specific force is explained within this
  bool compensate_acceleration = true;      // remove the estimated IMU acceleration before taking the tilt
  double acceleration_filter_s = 0.005;     // low-pass time constant of that acceleration estimate
};

struct ContactParams {
  ContactSource source = ContactSource::Switch;
  double force_on_N = 60.0;   // estimated normal force above which a foot is in contact
  double force_off_N = 30.0;  // ... and below which it leaves contact (hysteresis)
};

struct EstimatorConfig {
  std::string source_file;
  EstimatorMode mode = EstimatorMode::Kalman;
  double nominal_dt_s = 0.001;  // used when the time stamps do not advance
  double max_dt_s = 0.02;       // a larger gap is clamped (a stall must not blow up the prediction)
  KalmanParams kalman;
  PitchParams pitch;
  ContactParams contact;
  double ground_truth_contact_force_N = 1.0;  // bypass mode: contact when the true normal force exceeds this
};

// Throw mft::config::ConfigError naming the file and key.
EstimatorConfig loadEstimatorConfig(const std::string& path);
EstimatorConfig parseEstimatorConfig(const std::string& yaml_text, const std::string& origin);

}  // namespace mft::estimator
