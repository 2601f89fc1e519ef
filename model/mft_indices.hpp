#pragma once
// Local transmission index (LTI) of one planar five-bar leg: paper eq. 3-4, closed forms of docs/reference/five-bar-theory.md#transmission-indices-lti.
// ITI of chain i = |sin(knee_i)| = |e_i x u_i|, OTI = |u_r x u_f| (both chains), LTI = min of all three.
// Every value is finite and lies in [0, 1]; a singular configuration gives 0, never NaN.
#include "model/coordinates.hpp"
#include "model/five_bar.hpp"

namespace mft::model {

// Paper (1): the power efficiency of a force f on a point moving with velocity v, the sine of the transmission
// angle: sin(alpha) = |f . v| / (|f| |v|), in [0, 1] (rounding clamped). 0 when f or v is zero (no power can
// pass), never NaN.
double transmissionAngleSine(const Eigen::Vector2d& f, const Eigen::Vector2d& v);

// Planar screws in the (x, z) plane, angles counter-clockwise positive, both taken at the frame's origin.
struct PlanarTwist {
  double w = 0.0;                                   // angular velocity
  Eigen::Vector2d v = Eigen::Vector2d::Zero();      // velocity of the body point at the origin
  static PlanarTwist rotationAbout(const Eigen::Vector2d& center, double rate = 1.0);
};
struct PlanarWrench {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();      // force
  double m = 0.0;                                   // moment about the origin
  static PlanarWrench forceThrough(const Eigen::Vector2d& point, const Eigen::Vector2d& force);
};

// Reciprocal product of a wrench with a twist, the power the wrench delivers on the moving body: f . v + m w
// (independent of the origin both are taken at).
double reciprocalProduct(const PlanarWrench& wrench, const PlanarTwist& twist);

// Paper (2): the instantaneous input and output powers of one limb, P_I = |$_T o $_I| and P_O = |$_T o $_O|,
// for its transmission wrench $_T, input twist $_I and output twist $_O.
struct LimbPowers {
  double input = 0.0;   // P_I
  double output = 0.0;  // P_O
};
LimbPowers limbPowers(const PlanarWrench& transmission, const PlanarTwist& input, const PlanarTwist& output);

struct TransmissionIndices {
  double iti_rear = 0.0;  // input transmission index lambda_r
  double iti_fore = 0.0;  // lambda_f
  double oti = 0.0;       // output transmission index eta (gamma_O)
  double iti() const { return iti_rear < iti_fore ? iti_rear : iti_fore; }  // gamma_I
  double lti() const { return iti() < oti ? iti() : oti; }                 // gamma_LTI
};

// From a solved pose (any hip spacing): only link directions are used. Each index is (1) at unit force and
// speed: ITI_i with the force along shank i on its knee point, which moves perpendicular to thigh i; OTI with
// the force along the rear shank on the foot, which moves perpendicular to the fore shank when the fore hip is
// locked.
TransmissionIndices transmissionIndices(const FiveBarPose& pose);

// From the actuated angles. Degenerate (thighs coincide: the foot can spin about the common knee) gives the
// output singularity, all indices 0 except the ITIs that the geometry still defines. Unreachable gives zeros
// and returns the status so the caller can tell the two apart.
FiveBarStatus transmissionIndicesAt(const FiveBarGeometry& g, double q_rear, double q_fore, TransmissionIndices* out);

// LTI of leg `leg` (0 right, 1 left) straight from the generalized coordinates, as the WBC's diagnostics and the
// simulator's fall check use it: min(|sin knee_rear|, |sin knee_fore|, |sin(shank_fore - shank_rear)|), shank =
// hip + knee (absolute); the same indices as transmissionIndices() of the solved pose.
double legTransmissionIndex(const VectorQ& q, int leg);

}  // namespace mft::model
