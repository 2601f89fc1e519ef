#pragma once
// Local transmission index (LTI) of one planar five-bar leg: paper eq. 3-4, closed forms of docs/five-bar-theory.md#transmission-indices-lti.
// ITI of chain i = |sin(knee_i)| = |e_i x u_i|, OTI = |u_r x u_f| (both chains), LTI = min of all three.
// Every value is finite and lies in [0, 1]; a singular configuration gives 0, never NaN.
#include "model/coordinates.hpp"
#include "model/five_bar.hpp"

namespace mft::model {

struct TransmissionIndices {
  double iti_rear = 0.0;  // input transmission index lambda_r
  double iti_fore = 0.0;  // lambda_f
  double oti = 0.0;       // output transmission index eta (gamma_O)
  double iti() const { return iti_rear < iti_fore ? iti_rear : iti_fore; }  // gamma_I
  double lti() const { return iti() < oti ? iti() : oti; }                 // gamma_LTI
};

// From a solved pose (any hip spacing): only link directions are used.
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
