#pragma once
// Series elastic actuator as the joint sees it (docs/reference/five-bar-theory.md#robot-parameters-and-the-sea): the closed torque loop behaves as
//   tau'' + 2 zeta w tau' + w^2 tau = w^2 tau_in,
// integrated exactly for an input held over one physics step, so the response does not depend on the
// substep count. The motor limits act on tau_in (the drive cannot command more): output peak torque, and no
// torque in the direction of motion at the output speed limit (linear fade over a band below it).
namespace mft::sim {

struct SeaLimits {
  double peak_torque = 0.0;   // output peak torque [N m]
  double speed_limit = 0.0;   // output speed limit [rad/s]
  double speed_band = 1.0;    // fade band below the speed limit [rad/s]
};

class SeaActuator {
 public:
  SeaActuator() = default;
  // w, zeta: torque-loop natural frequency and damping ratio; h: physics step.
  SeaActuator(double w, double zeta, double h, const SeaLimits& limits);

  void reset(double torque);  // at rest at this output torque
  double torque() const { return tau_; }
  double rate() const { return tau_dot_; }

  // A torque after the drive limits at output speed omega (the simulator applies them to the SEA's input and
  // to its output).
  double limitedInput(double command, double omega) const;
  // One physics step with the (limited) input held constant.
  void advance(double input);

 private:
  double ad_[2][2] = {{1, 0}, {0, 1}};
  double bd_[2] = {0, 0};
  double tau_ = 0.0, tau_dot_ = 0.0;
  SeaLimits limits_;
};

// 2 % settling time of the loop's step response (for reports and tests), by simulation at step h.
double seaSettlingTime(double w, double zeta, double h);

// The physical SEA behind that filter (docs/reference/five-bar-theory.md#robot-parameters-and-the-sea), all in output-side units: a motor with reflected
// inertia J_r = n^2 J_m and reflected viscous friction b_r (on the motor speed), a spring k_s to the joint, and
// the drive's torque loop
//   tau_m = tau_d + Kp (tau_d - tau_s) - Kd dtau_s/dt,   tau_s = k_s (theta_m - theta_j),
//   J_r theta_m'' = tau_m - tau_s - b_r theta_m'.
// The joint receives tau_s. Kp and Kd place the locked-joint poles at w, zeta:
//   w^2 = k_s (1 + Kp) / J_r,   2 zeta w = (k_s Kd + b_r) / J_r,
// so with the joint held the spring torque follows tau'' + 2 zeta w tau' + w^2 tau = w^2 tau_d like SeaActuator;
// with the joint moving the motor has to accelerate J_r as well: at joint acceleration a the spring torque lags
// the command by (J_r a + b_r omega) / (1 + Kp) (loop unsaturated) and stays below peak - J_r a - b_r omega once
// tau_m saturates. Limits act on the motor: |tau_m| <= peak, and no drive torque in the direction of motor
// motion at the speed limit (the same linear fade as SeaActuator, on the motor speed).
// Discretisation: the torque loop runs digitally at loop_period (rounded down to a whole fraction of the
// physics step), its
// torque held over a loop period (zero-order hold); the motor and spring are integrated exactly over each loop
// period with that torque and the joint's mean rate over the physics step (the joint angle interpolated
// linearly, as ODE's integrator moves it).
struct SeaMotorParams {
  double reflected_inertia_kgm2 = 0.0;   // J_r = gear_ratio^2 * rotor_inertia
  double spring_stiffness_Nmprad = 0.0;  // k_s
  double reflected_damping_Nmsprad = 0.0;  // b_r
  double natural_frequency_radps = 0.0;  // w of the locked-joint loop
  double damping_ratio = 1.0;            // zeta of the locked-joint loop
  double loop_period_s = 1e-4;           // torque loop period
};

class SeaMotorActuator {
 public:
  SeaMotorActuator() = default;
  // h: physics step. Throws std::invalid_argument on non-physical parameters or gains (Kd < 0, Kp <= -1).
  SeaMotorActuator(const SeaMotorParams& params, double h, const SeaLimits& limits);

  // At rest relative to the joint (no deflection rate), the spring holding this torque.
  void reset(double torque, double joint_rate);
  double torque() const { return params_.spring_stiffness_Nmprad * deflection_; }  // tau_s on the joint
  double deflection() const { return deflection_; }                                 // theta_m - theta_j [rad]
  double motorSpeed() const { return motor_speed_; }                                // theta_m' [rad/s]
  double proportionalGain() const { return kp_; }
  double derivativeGain() const { return kd_; }  // [s]
  double meanMotorTorque() const { return mean_motor_torque_; }  // tau_m over the last physics step
  int loopStepsPerPhysicsStep() const { return loop_steps_; }

  // One physics step: command tau_d held, the joint turning at joint_rate (its mean rate over the step).
  void advance(double command, double joint_rate);

 private:
  double motorTorque(double command, double joint_rate) const;

  SeaMotorParams params_;
  SeaLimits limits_;
  double kp_ = 0.0, kd_ = 0.0;
  int loop_steps_ = 1;
  // Exact discretisation over one loop period of x = [deflection, motor speed], inputs u = [tau_m, joint rate].
  double ad_[2][2] = {{1, 0}, {0, 1}};
  double bd_[2][2] = {{0, 0}, {0, 0}};
  double deflection_ = 0.0, motor_speed_ = 0.0, mean_motor_torque_ = 0.0;
};

}  // namespace mft::sim
