#include "estimator/estimator_config.hpp"

#include "common/strict_yaml.hpp"

namespace mft::estimator {
namespace {

using config::EnumName;
using config::StrictNode;

constexpr EnumName<EstimatorMode> kModeNames[] = {{EstimatorMode::Kalman, "kalman"},
                                                  {EstimatorMode::GroundTruth, "ground_truth"}};
constexpr EnumName<ContactSource> kContactSourceNames[] = {{ContactSource::Switch, "switch"},
                                                           {ContactSource::Force, "force"},
                                                           {ContactSource::Either, "either"},
                                                           {ContactSource::Both, "both"}};

EstimatorConfig read(StrictNode& root) {
  root.useSchema("estimator");  // every number it reads is checked against its range (config_schema.hpp)
  EstimatorConfig c;
  c.mode = root.choice("mode", kModeNames);

  auto& timing = root.child("timing");
  c.nominal_dt_s = timing.positive("nominal_dt_s");
  c.max_dt_s = timing.positive("max_dt_s");
  if (c.max_dt_s < c.nominal_dt_s) timing.fail("max_dt_s", "must be >= nominal_dt_s");

  auto& kf = root.child("kalman");
  c.kalman.accel_noise_density = kf.positive("accel_noise_density_mps2_per_sqrt_hz");
  c.kalman.foot_slip_density = kf.positive("foot_slip_density_m_per_sqrt_s");
  c.kalman.kinematic_position_std_m = kf.positive("kinematic_position_std_m");
  c.kalman.kinematic_velocity_std_mps = kf.positive("kinematic_velocity_std_mps");
  c.kalman.use_ground_height = kf.boolean("use_ground_height");
  c.kalman.ground_height_m = kf.number("ground_height_m");
  c.kalman.ground_height_std_m = kf.positive("ground_height_std_m");
  c.kalman.initial_position_std_m = kf.positive("initial_position_std_m");
  c.kalman.initial_velocity_std_mps = kf.positive("initial_velocity_std_mps");

  auto& pitch = root.child("pitch");
  c.pitch.correction_time_constant_s = pitch.positive("correction_time_constant_s");
  c.pitch.gyro_bias_gain = pitch.nonNegative("gyro_bias_gain_per_s2");
  c.pitch.accel_gate_mps2 = pitch.positive("accel_gate_mps2");
  c.pitch.compensate_acceleration = pitch.boolean("compensate_acceleration");
  c.pitch.acceleration_filter_s = pitch.positive("acceleration_filter_s");

  auto& contact = root.child("contact");
  c.contact.source = contact.choice("source", kContactSourceNames);
  c.contact.force_on_N = contact.positive("force_on_N");
  c.contact.force_off_N = contact.nonNegative("force_off_N");
  if (c.contact.force_off_N > c.contact.force_on_N) contact.fail("force_off_N", "must be <= force_on_N (hysteresis)");

  auto& gt = root.child("ground_truth");
  c.ground_truth_contact_force_N = gt.nonNegative("contact_force_N");

  return c;
}

}  // namespace

EstimatorConfig loadEstimatorConfig(const std::string& path) { return config::loadStrictFile(path, read); }

EstimatorConfig parseEstimatorConfig(const std::string& yaml_text, const std::string& origin) {
  return config::parseStrictString(yaml_text, origin, read);
}

}  // namespace mft::estimator
