#include "model/mft_raci.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/enum_names.hpp"
#include "model/mft_indices.hpp"

namespace mft::model {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Below this |sin| the leg is treated as singular: torques would exceed any actuator by orders of magnitude.
constexpr double kSingularSin = 1e-9;

// Optimal-ratio worst case with gravity: max over |a| = a_max of min_k |k x + y / (eta k)|, x = u.a,
// y = w.a + g; the inner minimum is 2 sqrt(x y / eta) when x and y agree in sign, else 0. The outer maximum
// has no closed form with the offset g, so scan the circle and refine around the best angle.
double optimalWithGravity(const Eigen::Vector2d& u, const Eigen::Vector2d& w, double g, double amax, double eff) {
  auto value = [&](double phi) {
    const Eigen::Vector2d a = amax * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    const double xy = u.dot(a) * (w.dot(a) + g);
    return xy > 0.0 ? 2.0 * std::sqrt(xy / eff) : 0.0;
  };
  const int n = 360;
  double best_phi = 0.0, best = -1.0;
  for (int i = 0; i < n; ++i) {
    const double phi = 2.0 * M_PI * i / n;
    const double v = value(phi);
    if (v > best) best = v, best_phi = phi;
  }
  for (double step = 2.0 * M_PI / n; step > 1e-10; step *= 0.5) {
    for (double phi : {best_phi - step, best_phi + step}) {
      const double v = value(phi);
      if (v > best) best = v, best_phi = phi;
    }
  }
  return best;
}
}  // namespace

constexpr config::EnumName<RaciForm> kRaciFormNames[] = {{RaciForm::OptimalRatio, "optimal"},
                                                         {RaciForm::FixedDrive, "fixed"}};

const char* raciFormName(RaciForm f) { return config::nameOf(kRaciFormNames, f); }

bool parseRaciForm(const std::string& s, RaciForm* out) { return config::parseName(kRaciFormNames, s, out); }

RaciOptions RaciOptions::fromRobot(const RobotDescription& d) {
  RaciOptions o;
  o.drive_k = d.actuator.gear_ratio * std::sqrt(d.actuator.rotor_inertia_kgm2);
  o.gearbox_efficiency = d.actuator.gearbox_efficiency;
  o.gravity_mps2 = d.gravity_mps2;
  return o;
}

double actuatorRaciLimit(const ActuatorParams& a) { return a.motor_peak_torque_Nm / std::sqrt(a.rotor_inertia_kgm2); }

Eigen::Matrix2d fiveBarInverseJacobian(const FiveBarGeometry& g, const FiveBarPose& p) {
  Eigen::Matrix2d U;
  const double q[2] = {p.q_rear, p.q_fore};
  const double alpha[2] = {p.shank_rear, p.shank_fore};
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d u = linkDirection(alpha[i]);
    const double sigma = cross2(linkDirection(q[i]), u);  // sin(knee_i)
    U.row(i) = u.transpose() / (g.l1 * sigma);
  }
  return U;
}

RaciResult computeRaci(const FiveBarGeometry& g, const LegInertiaParams& m, const FiveBarPose& p, const RaciOptions& o) {
  RaciResult r;
  const TransmissionIndices t = transmissionIndices(p);
  if (t.iti_rear < kSingularSin || t.iti_fore < kSingularSin || t.oti < kSingularSin) {
    r.raci = r.tau_rear = r.tau_fore = kInf;
    r.singular = true;
    return r;
  }
  const Eigen::Matrix2d U = fiveBarInverseJacobian(g, p);
  const Eigen::Matrix2d W = legActuatedInertia(g, m, p) * U;
  Eigen::Vector2d G = Eigen::Vector2d::Zero();
  if (o.gravity) G = legGravityTorque(g, m, p, o.gravity_mps2);
  const double eff = o.gearbox_efficiency, amax = o.accel_max_mps2, k = o.drive_k;
  double tau[2];
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d u = U.row(i).transpose(), w = W.row(i).transpose();
    if (o.form == RaciForm::FixedDrive) {
      tau[i] = amax * (k * u + w / (eff * k)).norm() + std::abs(G[i]) / (eff * k);
    } else if (!o.gravity) {
      // Largest eigenvalue of the symmetric part of u w' is (|u||w| + u.w) / 2; clamp rounding below 0.
      tau[i] = amax * std::sqrt(std::max(0.0, 2.0 * (u.norm() * w.norm() + u.dot(w)) / eff));
    } else {
      tau[i] = optimalWithGravity(u, w, G[i], amax, eff);
    }
  }
  r.tau_rear = tau[0];
  r.tau_fore = tau[1];
  r.raci = std::max(tau[0], tau[1]);
  return r;
}

}  // namespace mft::model
