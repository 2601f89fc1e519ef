#pragma once
// Controller parameters (config/wbc.yaml): variant, task weights (paper Table I), PD gains (17), limits,
// contact model, SA-WBC passive-joint bounds (20) and the safety stage. The defaults of this struct are
// the values of the shipped config/wbc.yaml, so tests can build a controller without a file.
#include <Eigen/Core>
#include <string>

#include "model/robot_description.hpp"

namespace mft::wbc {

// Which Problem 1 is solved (one code path, rows and bounds switched at construction):
//   Mft  - the paper: soft MFT polytope C qdd <= d + eps, eps weighted by w_eps.
//   Sa   - SA-WBC baseline: no MFT rows, eps fixed to 0 by bounds, passive-joint bound of (20).
//   None - neither (ablation).
enum class WbcVariant { Mft, Sa, None };
const char* toString(WbcVariant v);
// Parses "mft", "sa" or "none"; returns false for anything else.
bool parseVariant(const std::string& text, WbcVariant* out);

struct PdGains1 {
  double kp = 0.0;  // [1/s^2]
  double kd = 0.0;  // [1/s]
};
struct PdGains2 {  // per world axis [x, z]
  Eigen::Vector2d kp{0.0, 0.0};
  Eigen::Vector2d kd{0.0, 0.0};
};

struct WbcWeights {  // paper Table I, plus the qdd regularization that keeps H positive definite
  double base_z = 1.0;
  double base_pitch = 1.0;
  double swing_foot = 1.0;
  double support_foot = 1.0e2;
  double contact_force = 1.0e-3;
  double contact_force_rate = 5.0e-2;
  double slack = 1.0e3;
  double qdd_regularization = 1.0e-3;
  // Not in Table I: base x task, active only when standing in double support (WbcReference::hold_base_x).
  double base_x = 100.0;  // config/wbc.yaml: outweighs w_fc m^2 (Table I)
};

struct WbcGains {
  PdGains1 base_z{400.0, 40.0};
  PdGains1 base_pitch{400.0, 40.0};
  PdGains2 swing_foot{{400.0, 400.0}, {40.0, 40.0}};
  PdGains2 support_foot{{0.0, 0.0}, {20.0, 20.0}};
  PdGains1 base_x{100.0, 20.0};  // standing only (see WbcWeights::base_x)
};

struct WbcLimits {
  Eigen::Vector3d qdd_base_max{20.0, 20.0, 20.0};  // |qdd| of [x, z, pitch]: [m/s^2, m/s^2, rad/s^2]
  double qdd_joint_max_radps2 = 22.0;              // |qdd| of every leg joint
  double torque_limit_fraction = 1.0;              // of the actuator output peak torque (robot.yaml)
};

struct WbcContact {
  // Pyramid |f_x| <= mu f_z with mu = friction_fraction * robot.yaml contact.friction_coefficient: the QP and
  // the simulated ground share one coefficient.
  double friction_fraction = 1.0;
  double normal_force_max_N = 1000.0;  // f_z upper bound of a stance foot (a swing foot gets 0)
};

struct WbcSaBounds {  // (20): singularity boundaries of the passive knees (with the robot's sign per knee)
  model::Interval rear_knee_rad{0.0, 3.141592653589793};    // q5, q9: the singularities 0 and pi
  model::Interval fore_knee_rad{-3.141592653589793, 0.0};   // q7, q11: the singularities -pi and 0
};

struct WbcSafety {
  int hold_ticks = 5;                 // ticks the last good command is held after a failure, then damping
  double damping_Nms_per_rad = 2.0;   // damping command tau = -k qd_a (sent with CommandMode::Damping)
  bool latch_damping = false;         // true: stay in damping until reset(), even if solves succeed again
};

struct WbcConfig {
  std::string source_file;  // where it was loaded from ("" = defaults)
  WbcVariant variant = WbcVariant::Mft;
  // MFT / SA prediction horizon dt = horizon_settling_times * actuator.sea.settling_time_s (paper: 2 t_s).
  double horizon_settling_times = 2.0;
  WbcWeights weights;
  WbcGains gains;
  WbcLimits limits;
  WbcContact contact;
  WbcSaBounds sa;
  WbcSafety safety;
};

// Strict loading (mft::config::ConfigError naming file and key for a missing, unknown or invalid key).
WbcConfig loadWbcConfig(const std::string& path);
WbcConfig parseWbcConfig(const std::string& yaml_text, const std::string& origin);
// Checks that need the robot (SA bounds inside the robot's knee ranges, horizon > 0). Throws ConfigError.
void validateWbcConfig(const WbcConfig& c, const model::RobotDescription& robot);

}  // namespace mft::wbc
