// Protection level: a bound on the pose error published with every pose (the "protection level" of
// GNSS integrity monitoring, RAIM). Two parts, as in aviation practice:
//   PL_xy = K_xy · sqrt(λ_max(P_xy)) + b_xy,   PL_θ = K_θ · sqrt(P_θθ) + b_θ
// - the stochastic part from the tracker's covariance P: K_xy = sqrt(−2 ln α) bounds the radial
//   error of a 2-D Gaussian whose both axes had the larger variance (Rayleigh tail: P(r > Kσ) =
//   exp(−K²/2) = α), K_θ the two-sided normal quantile at α;
// - a bias part the covariance cannot see because it does not average out over scans: the map's
//   own error. b_xy = map cell + RMS residual of the scan's inliers (quantisation, plus how far
//   the map's walls are from where the scan sees them here and now), b_θ = b_xy / lever (the
//   angle that shift makes at the RMS distance of the inliers, lever ≥ 1 m).
// α is the integrity risk per `localized` step (1e-3 by default).
#pragma once

#include <Eigen/Core>

namespace fw {
namespace track {

struct ProtectionLevel {
  float xy_m = 0.0f;
  float theta_rad = 0.0f;
};

// K_xy = sqrt(−2 ln α).
float radial_factor(float risk);
// K_θ: two-sided standard normal quantile, P(|z| > K) = α (bisection on erfc; start-up only).
float two_sided_factor(float risk);

struct ProtectionFactors {
  float k_xy = 0.0f, k_theta = 0.0f;
  static ProtectionFactors for_risk(float risk) { return {radial_factor(risk), two_sided_factor(risk)}; }
};

ProtectionLevel protection_level(const Eigen::Matrix3f& cov, const ProtectionFactors& k, float bias_xy_m,
                                 float bias_theta_rad);

}  // namespace track
}  // namespace fw
