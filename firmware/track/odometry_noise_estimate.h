// Wheel-noise self-calibration of the tracker (extension; not in the dissertation; OFF by default,
// TrackOptions::odom_noise_window says why: on real wheels it raised the PL exceedance). The odometry
// noise model (AMCL's α, track_options.h) is a property of the robot that a deployer may not know:
// the default α = 0.2 says 11° of heading error per metre driven, 4–20× what good wheels do, and
// that looseness alone ends tracks that the scans still hold (fr-campus, 0.9 m between scans: three
// scans the map cannot explain grew the prediction's PL past the 2 m lost limit at a right pose).
// So the tracker measures its wheels: every increment between two scan fixes of a trusted track is
// compared with the odometry's increment, normalised by the model's variance for that motion, and
// the model is scaled by an upper confidence bound on the ratio (χ² at the integrity risk), so a
// window that happens to be quiet does not promise more than the data shows.
//
// Only increments where the model's variance dominates both fixes' own (scan) variance count (a 5 cm
// step indoors says more about the scan matcher than about the wheels; a corridor leaves its axis
// unmeasured): those samples make the bound conservative, never optimistic. Translation (2 degrees
// of freedom per sample) and heading (1) are scaled separately. Fixed storage, no heap.
#pragma once

#include <cstdint>

namespace fw {
namespace track {

struct OdometryNoiseScale {
  float trans = 1.0f;  // multiplies odom_trans_per_m and odom_trans_per_rad
  float rot = 1.0f;    // multiplies odom_rot_per_rad and odom_rot_per_m
  std::uint32_t trans_samples = 0, rot_samples = 0;
};

class OdometryNoiseEstimate {
 public:
  static constexpr std::uint32_t kMaxWindow = 128;
  // window 0 = off (scale 1). The scale stays 1 until min_samples increments are in the window,
  // then it is the upper confidence bound at `risk`, clamped to [min_scale, max_scale].
  void configure(std::uint32_t window, std::uint32_t min_samples, float min_scale, float max_scale, float risk);
  void clear();
  // One increment: squared residual (fix increment ⊖ odometry increment) and the model's variance
  // for that motion at the configured α (per axis for translation).
  void add_translation(float residual_sq, float model_var);
  void add_rotation(float residual_sq, float model_var);
  const OdometryNoiseScale& scale() const { return scale_; }

 private:
  struct Ring {
    float ratio[kMaxWindow] = {};
    std::uint32_t count = 0, next = 0;
  };
  void push(Ring* r, float ratio);
  float bound(const Ring& r, float dof_per_sample) const;
  void update();
  Ring trans_, rot_;
  std::uint32_t window_ = 0, min_samples_ = 0;
  float min_scale_ = 1.0f, max_scale_ = 1.0f, z_ = 3.09f;
  OdometryNoiseScale scale_;
};

// Lower quantile of χ²(k) at the standard normal z (z < 0), Wilson–Hilferty.
float chi2_lower_quantile(float k, float z);

}  // namespace track
}  // namespace fw
