#pragma once
// Series elastic actuator as the joint sees it (MFT-THEORY.md 4.2): the closed torque loop behaves as
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

}  // namespace mft::sim
