#include "estimator/state_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mft::estimator {

namespace {
Eigen::Matrix2d rotation(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix2d() << c, -s, s, c).finished();
}
const Eigen::Matrix2d kJ = (Eigen::Matrix2d() << 0.0, -1.0, 1.0, 0.0).finished();  // dR/da = R J
}  // namespace

StateEstimator::StateEstimator(const EstimatorConfig& config, const model::RobotDescription& robot)
    : config_(config),
      geometry_(model::FiveBarGeometry::from(robot)),
      gravity_(robot.gravity_mps2),
      imu_in_base_(robot.imu_position_m[0], robot.imu_position_m[1]),
      pitch_(config.pitch, robot.gravity_mps2),
      kf_(config.kalman),
      contact_(config.contact, geometry_) {}

const model::RobotStateEstimate& StateEstimator::update(const model::SensorReadings& readings,
                                                        const model::GroundTruthState* truth) {
  if (config_.mode == EstimatorMode::Kalman) return updateKalman(readings);
  if (truth == nullptr) throw std::invalid_argument("estimator in ground_truth mode needs a GroundTruthState");
  return updateGroundTruth(*truth);
}

const model::RobotStateEstimate& StateEstimator::updateGroundTruth(const model::GroundTruthState& truth) {
  out_.tick = truth.tick;
  out_.time_s = truth.time_s;
  out_.q = truth.q;
  out_.qd = truth.qd;
  for (int leg = 0; leg < model::kNumLegs; ++leg)
    out_.contact[leg] = truth.contact_force[2 * leg + 1] > config_.ground_truth_contact_force_N;
  return out_;
}

void StateEstimator::legKinematics(const model::SensorReadings& s) {
  for (int leg = 0; leg < model::kNumLegs; ++leg) feet_[leg] = footInBase(geometry_, legJoints(s, leg));
}

void StateEstimator::initialize(const Eigen::Vector3d& pose, const Eigen::Vector3d& rate,
                                const model::SensorReadings& s) {
  legKinematics(s);
  const Eigen::Matrix2d R = rotation(pose[2]);
  const Eigen::Vector2d p_imu = pose.head<2>() + R * imu_in_base_;
  const Eigen::Vector2d v_imu = rate.head<2>() + rate[2] * R * kJ * imu_in_base_;
  BaseKalmanFilter::LegArray feet;
  for (int leg = 0; leg < model::kNumLegs; ++leg) feet[leg] = pose.head<2>() + R * feet_[leg].pos;
  kf_.reset(p_imu, v_imu, feet);
  pitch_.reset(pose[2]);
  contact_.reset();
  accel_est_.setZero();
  last_time_ = s.time_s;
  initialized_ = true;
}

const model::RobotStateEstimate& StateEstimator::updateKalman(const model::SensorReadings& s) {
  const Eigen::Vector2d f_body(s.accel[0], s.accel[1]);
  if (!initialized_) {
    legKinematics(s);
    const double pitch = tiltFromSpecificForce(f_body, Eigen::Vector2d::Zero(), gravity_);
    const Eigen::Matrix2d R = rotation(pitch);
    // Base height: the lowest foot among those in contact (all feet if none) rests on the ground.
    const auto contact = contact_.update(s, pitch);
    const bool any = contact[0] || contact[1];
    double lowest = 0.0;
    bool first = true;
    for (int leg = 0; leg < model::kNumLegs; ++leg) {
      if (any && !contact[leg]) continue;
      const double z = (R * feet_[leg].pos).y();
      if (first || z < lowest) lowest = z;
      first = false;
    }
    initialize({0.0, config_.kalman.ground_height_m - lowest, pitch}, Eigen::Vector3d::Zero(), s);
  }

  double dt = s.time_s - last_time_;
  if (!(dt > 0.0)) dt = config_.nominal_dt_s;
  dt = std::min(dt, config_.max_dt_s);
  last_time_ = s.time_s;

  legKinematics(s);
  stance_ = contact_.update(s, pitch_.pitch());

  pitch_.update(s.gyro_pitch_rate, f_body, accel_est_, dt);
  const double th = pitch_.pitch(), thd = pitch_.rate();
  const Eigen::Matrix2d R = rotation(th);

  const Eigen::Vector2d v_before = kf_.velocity();
  kf_.predict(R * f_body - Eigen::Vector2d(0.0, gravity_), dt);
  BaseKalmanFilter::LegArray rel, rel_rate;
  for (int leg = 0; leg < model::kNumLegs; ++leg) {
    const Eigen::Vector2d d = feet_[leg].pos - imu_in_base_;
    rel[leg] = R * d;
    rel_rate[leg] = thd * R * kJ * d + R * feet_[leg].vel;
  }
  kf_.correct(rel, rel_rate, stance_);

  // IMU acceleration for the tilt compensation: low-passed rate of the filtered velocity.
  const double alpha = dt / (config_.pitch.acceleration_filter_s + dt);
  accel_est_ += alpha * ((kf_.velocity() - v_before) / dt - accel_est_);

  fillOutput(s);
  return out_;
}

void StateEstimator::fillOutput(const model::SensorReadings& s) {
  const double th = pitch_.pitch(), thd = pitch_.rate();
  const Eigen::Matrix2d R = rotation(th);
  out_.tick = s.tick;
  out_.time_s = s.time_s;
  out_.q.head<2>() = kf_.position() - R * imu_in_base_;
  out_.q[model::kBasePitch] = th;
  out_.qd.head<2>() = kf_.velocity() - thd * R * kJ * imu_in_base_;
  out_.qd[model::kBasePitch] = thd;
  for (int i = 0; i < model::kNa; ++i) {
    out_.q[model::kActuatedIndex[i]] = s.actuated_pos[i];
    out_.qd[model::kActuatedIndex[i]] = s.actuated_vel[i];
    out_.q[model::kPassiveIndex[i]] = s.passive_pos[i];
    out_.qd[model::kPassiveIndex[i]] = s.passive_vel[i];
  }
  out_.contact = stance_;
}

}  // namespace mft::estimator
