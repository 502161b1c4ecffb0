// MclOptions: the MCL baseline of App. A / Sec. 5.7.2 plus what AMCL users expect (likelihood
// field, KLD-sampling, random-particle injection), all in one validated struct.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {
namespace mcl {

// Compile-time particle maximum: the thesis used up to 120,000 (MIT Killian Court).
constexpr std::size_t kMaxParticles = 131072;
constexpr std::size_t kMaxBeams = 64;
constexpr std::size_t kMaxConstraintWindow = 64;
// Particles are processed in this many fixed chunks, each with its own RandomStream, so the
// result does not depend on the number of worker threads.
constexpr std::size_t kChunks = 64;

enum class SensorModel : std::uint8_t { kBeam = 0, kLikelihoodField = 1 };

struct MclOptions {
  std::uint32_t num_particles = 30000;  // ≤ kMaxParticles (15k–120k in the thesis)
  SensorModel model = SensorModel::kBeam;
  std::uint32_t num_beams = 18;         // App. A: 18 beams
  float max_range_m = 8.0f;             // SICK LMS useful range in the experiments

  // Beam model (Thrun et al., Probabilistic Robotics Table 6.1).
  float z_hit = 0.80f, z_short = 0.05f, z_max = 0.05f, z_rand = 0.10f;
  float sigma_hit_m = 0.20f;
  float lambda_short = 0.5f;
  // Likelihood-field model (Table 6.3).
  float lf_sigma_m = 0.20f;
  // Per-beam log-likelihood floor: robust against unmodelled obstacles.
  float min_beam_log_likelihood = -6.0f;

  // Odometry motion model (Table 5.6): α1 rot←rot, α2 rot←trans, α3 trans←trans, α4 trans←rot.
  float alpha1 = 0.10f, alpha2 = 0.05f, alpha3 = 0.10f, alpha4 = 0.05f;
  float min_trans_noise_m = 0.01f, min_rot_noise_rad = 0.005f;

  // Resampling.
  float resample_neff_ratio = 0.5f;  // resample when N_eff < ratio·N (1 = every step)
  bool kld_sampling = false;         // Fox 2003
  float kld_epsilon = 0.05f, kld_z = 2.33f;  // z: upper 1−δ quantile (δ = 0.01)
  float kld_bin_xy_m = 0.5f, kld_bin_theta_rad = 0.1745f;
  std::uint32_t kld_min_particles = 500;
  bool random_injection = false;     // augmented MCL (Table 8.3)
  float alpha_slow = 0.001f, alpha_fast = 0.1f;

  // Localization constraint of the thesis: variance of ‖x_best − g(x_best,prev, u)‖ over τ steps.
  std::uint32_t tau = 10;
  float localized_variance_m2 = 0.01f;
  float localized_mean_m = 0.5f;     // and its mean (a constant large offset is no convergence)
  // AMCL-style convergence on top: at least this weight fraction within estimate_radius_m of the
  // best particle (one mode). 0 = the thesis's constraint alone.
  float localized_min_mass = 0.9f;

  // Output pose: weighted mean of the particles within this radius of the best particle.
  float estimate_radius_m = 1.0f;

  // Update gate (AMCL's update_min_d / update_min_a): the sensor update and resampling run only
  // once the odometry moved at least update_min_d metres or turned update_min_a radians since the
  // last update (the first scan after a reset / start_tracking is always used). Without it a robot
  // standing still re-weights and resamples the same scan over and over: the weights become
  // overconfident in one scan, the motion model's noise floor (min_trans_noise_m /
  // min_rot_noise_rad) diffuses the cloud between them and resampling picks a random walk, so the
  // estimate drifts although nothing moves. Gated steps publish the last estimate moved by the
  // odometry. AMCL's defaults (0.2 m, π/6) skip every other scan of the 15 cm scan spacing of the
  // thesis's logs and a whole in-place turn step; 0.10 m / 0.10 rad still updates at every such
  // scan and gates only standing still and creeping. 0, 0: every scan (the thesis's App. A filter).
  float update_min_d = 0.10f;
  float update_min_a = 0.10f;

  std::uint64_t seed = 1;

  Status validate() const;
};

}  // namespace mcl
}  // namespace fw
