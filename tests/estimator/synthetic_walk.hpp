#pragma once
// Synthetic sensor data from a known motion: the base follows smooth analytic x, z, pitch trajectories
// (forward walk with per-step oscillations), stance feet stay fixed in the world, the swing foot moves from its
// last foothold to the next, the joint angles come from the five-bar inverse kinematics and the IMU signals are
// computed exactly (gyro = pitch rate, specific force at the IMU point in the body frame). Optional noise.
#include <Eigen/Core>
#include <cmath>
#include <random>
#include <stdexcept>

#include "model/five_bar.hpp"
#include "model/robot_description.hpp"
#include "model/robot_io.hpp"

namespace mft::test {

struct WalkOptions {
  double speed = 0.3, height = 0.42, step = 0.35, lift = 0.05;
  double x_amp = 0.005, z_amp = 0.005, pitch_amp = 0.05;  // oscillations [m, m, rad]
  double gyro_std = 0.0, gyro_bias = 0.0, accel_std = 0.0, encoder_std = 0.0, encoder_vel_std = 0.0;
  unsigned seed = 1;
};

class SyntheticWalk {
 public:
  SyntheticWalk(const model::RobotDescription& d, const WalkOptions& o)
      : g_(model::FiveBarGeometry::from(d)), grav_(d.gravity_mps2), imu_(d.imu_position_m[0], d.imu_position_m[1]),
        o_(o), rng_(o.seed) {}

  // Base [x, z, pitch] and its first and second time derivatives.
  void base(double t, Eigen::Vector3d* p, Eigen::Vector3d* v, Eigen::Vector3d* a) const {
    const double w = 2.0 * M_PI / o_.step;
    *p << o_.speed * t + o_.x_amp * std::sin(w * t), o_.height + o_.z_amp * std::sin(w * t + 0.3),
        o_.pitch_amp * std::sin(0.5 * w * t + 0.7);
    *v << o_.speed + o_.x_amp * w * std::cos(w * t), o_.z_amp * w * std::cos(w * t + 0.3),
        o_.pitch_amp * 0.5 * w * std::cos(0.5 * w * t + 0.7);
    *a << -o_.x_amp * w * w * std::sin(w * t), -o_.z_amp * w * w * std::sin(w * t + 0.3),
        -o_.pitch_amp * 0.25 * w * w * std::sin(0.5 * w * t + 0.7);
  }
  // Foothold placed at time j * step, half a step ahead of the base.
  Eigen::Vector2d foothold(int j) const {
    Eigen::Vector3d p, v, a;
    base(j * o_.step, &p, &v, &a);
    return {p.x() + 0.5 * o_.speed * o_.step, 0.0};
  }
  // Step k: leg k % 2 swings from foothold k-1 to foothold k+1, the other stands on foothold k.
  int swingLeg(double t) const { return parity(static_cast<int>(std::floor(t / o_.step))); }
  static int parity(int k) { return ((k % 2) + 2) % 2; }  // also for negative k (finite differences at t = 0)
  Eigen::Vector2d footWorld(int leg, double t) const {
    const int k = static_cast<int>(std::floor(t / o_.step));
    if (leg != parity(k)) return foothold(k);
    const double s = t / o_.step - k;
    const Eigen::Vector2d a = foothold(k - 1), b = foothold(k + 1);
    const double blend = s * s * (3.0 - 2.0 * s);
    return {a.x() + (b.x() - a.x()) * blend, o_.lift * std::sin(M_PI * s) * std::sin(M_PI * s)};
  }
  // Generalized coordinates at t (legs by inverse kinematics).
  model::VectorQ q(double t) const {
    Eigen::Vector3d p, v, a;
    base(t, &p, &v, &a);
    model::VectorQ out = model::VectorQ::Zero();
    out.head<3>() = p;
    const Eigen::Matrix2d R = rot(p.z());
    for (int leg = 0; leg < 2; ++leg) {
      const Eigen::Vector2d d = R.transpose() * (footWorld(leg, t) - p.head<2>());
      model::FiveBarPose pose;
      if (model::fiveBarInverse(g_, d, &pose) != model::FiveBarStatus::Ok) throw std::runtime_error("unreachable");
      const auto c = model::legCoordinates(pose);
      for (int i = 0; i < 4; ++i) out[3 + 4 * leg + i] = c[i];
    }
    return out;
  }

  struct Sample {
    model::SensorReadings readings;
    model::GroundTruthState truth;
  };
  Sample sample(double t, std::uint64_t tick) {
    Eigen::Vector3d p, v, a;
    base(t, &p, &v, &a);
    const double h = 1e-6;
    const model::VectorQ qq = q(t), qd_fd = (q(t + h) - q(t - h)) / (2 * h);
    Sample s;
    s.truth.tick = s.readings.tick = tick;
    s.truth.time_s = s.readings.time_s = t;
    s.truth.q = qq;
    s.truth.qd = qd_fd;
    s.truth.qd.head<3>() = v;
    const int swing = swingLeg(t);
    for (int leg = 0; leg < 2; ++leg) {
      s.readings.contact[leg] = leg != swing;
      s.truth.contact_force[2 * leg + 1] = leg != swing ? 225.0 : 0.0;
    }
    std::normal_distribution<double> n(0.0, 1.0);
    for (int i = 0; i < model::kNa; ++i) {
      s.readings.actuated_pos[i] = qq[model::kActuatedIndex[i]] + o_.encoder_std * n(rng_);
      s.readings.passive_pos[i] = qq[model::kPassiveIndex[i]] + o_.encoder_std * n(rng_);
      s.readings.actuated_vel[i] = qd_fd[model::kActuatedIndex[i]] + o_.encoder_vel_std * n(rng_);
      s.readings.passive_vel[i] = qd_fd[model::kPassiveIndex[i]] + o_.encoder_vel_std * n(rng_);
    }
    // IMU point: a_imu = a_base + thdd R J r - thd^2 R r; specific force = R' (a_imu - g).
    const Eigen::Matrix2d R = rot(p.z()), J = (Eigen::Matrix2d() << 0, -1, 1, 0).finished();
    const Eigen::Vector2d a_imu = a.head<2>() + a.z() * R * J * imu_ - v.z() * v.z() * R * imu_;
    const Eigen::Vector2d f = R.transpose() * (a_imu + Eigen::Vector2d(0.0, grav_));
    s.readings.accel = {f.x() + o_.accel_std * n(rng_), f.y() + o_.accel_std * n(rng_)};
    s.readings.gyro_pitch_rate = v.z() + o_.gyro_bias + o_.gyro_std * n(rng_);
    return s;
  }

  static Eigen::Matrix2d rot(double a) {
    return (Eigen::Matrix2d() << std::cos(a), -std::sin(a), std::sin(a), std::cos(a)).finished();
  }

 private:
  model::FiveBarGeometry g_;
  double grav_;
  Eigen::Vector2d imu_;
  WalkOptions o_;
  std::mt19937 rng_;
};

}  // namespace mft::test
