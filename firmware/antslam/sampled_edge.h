// An AntSLAM edge (Ch. 3, SPEC §2): the transformation T(F_i → F_j) between two fragment frames as
// a Gaussian N(μ_ij, Σ_ij) and S = |T| options drawn from it (Eq. 3.10). The options are kept in
// the forward direction i → j; the reverse direction j → i uses their inverses (⊖t), so an edge
// holds its options "both ways" without storing them twice. Option 0 is μ_ij itself, so the
// uncorrected map is always one of the hypotheses an ant can pick.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"

namespace fw::antslam {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

struct SampledEdge {
  std::uint32_t from = 0, to = 0;  // fragment indices: mean = F_from ⊖ F_to (F_to in F_from)
  Se2d mean;                       // μ_ij
  Mat3 cov = Mat3::Identity();     // Σ_ij
  Mat3 info = Mat3::Identity();    // Σ_ij⁻¹
  // The motion model's covariance of the edge (Eq. 3.4): how far the front end may have drifted
  // along it, for predicting a path of edges (AntSLAM's loop candidates and gate). = cov unless
  // the caller sets it (antslam.h: Σ from the sensor model, Eq. 3.9).
  Mat3 predict_cov = Mat3::Identity();
  Se2d value;                      // the transform the map currently uses (μ until corrected)
  bool frozen = false;             // corrected by a loop: never changed again
  bool closure = false;            // a loop-closing edge (pRANSAM), not an adjacent pair
  Se2d* options = nullptr;         // S options (forward), from the arena
  double* option_cost = nullptr;   // (t − μ)ᵀ Σ⁻¹ (t − μ) of each option (first term of Eq. 3.13)
  std::uint32_t num_options = 0;
};

// t − μ with the angle wrapped (the difference the costs of Eq. 3.13 use).
inline Vec3 se2_difference(const Se2d& t, const Se2d& mu) {
  return Vec3(t.x - mu.x, t.y - mu.y, wrap_angle(t.theta - mu.theta));
}

// (t − μ)ᵀ Σ⁻¹ (t − μ).
inline double mahalanobis2(const Se2d& t, const Se2d& mu, const Mat3& info) {
  const Vec3 d = se2_difference(t, mu);
  return d.dot(info * d);
}

// Sets mean, covariance, information and value, and draws the options (Eq. 3.10: t = μ + L z,
// z ~ N(0, I), L Lᵀ = Σ; option 0 = μ). `options`/`option_cost` must hold `count` entries.
// Errors: covariance not symmetric positive definite, non-finite mean, count 0.
Status init_sampled_edge(std::uint32_t from, std::uint32_t to, const Se2d& mean, const Mat3& cov, Se2d* options,
                         double* option_cost, std::uint32_t count, RandomStream& rng, SampledEdge* edge);

// The transform of option k when the edge is walked from `from` to `to` (forward) or back.
inline Se2d edge_option(const SampledEdge& e, std::uint32_t k, bool forward) {
  return forward ? e.options[k] : e.options[k].inverse();
}

}  // namespace fw::antslam
