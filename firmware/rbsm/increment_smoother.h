// Rauch–Tung–Striebel smoothing of IncrementFusion's scans (extension of Alg. 1, issue 15).
//
// Why: the filter's pose at scan k has seen RBSM's poses up to k only, so every RBSM correction
// lands as a small jump at the scan it arrives and the relative motion between two nearby scans
// carries those jumps (the short relations). The smoother runs the same linearised model
// backwards, so scan k also hears the scans after it: a correction is spread over the scans that
// led to it, and the relative motion follows the precise increments more closely while the whole
// chain stays anchored to RBSM's map. With the filter's own models it is the maximum-a-posteriori
// estimate of the linearised chain, so nothing new is tuned:
//   C_k = P_k F_{k+1}ᵀ P̂_{k+1}⁻¹
//   x_k^s = x_k + C_k (x_{k+1}^s − x̂_{k+1})        (components, heading wrapped)
//   P_k^s = P_k + C_k (P_{k+1}^s − P̂_{k+1}) C_kᵀ
// with P_k, x_k the filtered state, x̂_{k+1}, P̂_{k+1} the prediction into k+1 and F_{k+1} its
// transition (FusionStep). The last scan stays as filtered.
//
// Offline (mml-slam's front end, mml-rbsm-eval) the steps are the whole log. Onboard the caller
// keeps the last L steps in a fixed array and smooths them after each scan, reading the pose of
// scan t−L (a fixed-lag smoother: L scans of latency, 264 bytes per scan). No heap; errors as Status.
#pragma once

#include <cstddef>

#include "firmware/base/status.h"
#include "firmware/rbsm/increment_fusion.h"

namespace fw {

// Smooths steps[0, n) in place (pose and cov); steps[n − 1] is left as filtered. An error names the
// step whose predicted covariance is not invertible (the steps were not produced by the filter);
// the steps before that one are then left as filtered.
Status smooth_fusion_steps(FusionStep* steps, std::size_t n);

}  // namespace fw
