// OdometryConsistency: does the track move the way the wheels say, over the last few fused scans?
// (extension; a windowed form of the Kalman filter's innovation test, Bar-Shalom's "time-averaged
// innovation" idea applied to the motion between two fused poses).
// The per-scan innovation test (pose_tracker.cpp) compares one scan fix with one odometry step; a
// scan matcher held by a wrong feature (a map that lacks what the robot sees, a look-alike end of a
// corridor) pulls the pose back a little at every scan, each pull within that scan's bound, while the
// wheels say the robot travels on: intel with an 8 m box erased, the track stayed within 0.4 m of
// one spot while the robot drove 2.7 m (the per-scan χ² fired at only one scan in six). Here every
// fused pose is kept with its covariance, and the odometry since then is composed with its own noise
// (the same model as the prediction, Q(Δ)); a new posterior x is tested against each kept pose x_i:
//   d = x ⊖ (x_i ⊕ u_i),   C = J₁ P_i J₁ᵀ + J₂ Q_i J₂ᵀ + P + B_i + B,   χ² = dᵀ C⁻¹ d,
// with B the map-bias terms of the protection level (diagonal, one per end: the map error does not
// average out). P_i and P are correlated positively through the shared map and chain, so adding them
// bounds the variance of the difference from above: the test errs towards availability.
// The wheels' systematic error (a scale error ε of the distance driven and of the angle turned,
// TrackOptions::odom_scale_error; UMBmark's wheel-diameter and wheelbase errors) is not noise: over a
// kept motion of path length D and accumulated turn A it adds (ε·A)² to the heading variance and
// (ε·D + ε·A·D)² to the position's (the heading error acting over the path, a bound), the same
// assumption the protection level makes (PL += ε·D_unpinned). Without it a base
// whose wheels over-report 3 % failed this test at right poses every few metres (corpus seed 404,
// poorly calibrated bases: each failure a large fault, the track waiting for MML for tens of metres).
// A failed test is a contradiction of the pose by the odometry, exactly like a failed innovation test.
// Fixed capacity; never allocates.
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "firmware/base/se2.h"

namespace fw {
namespace track {

class OdometryConsistency {
 public:
  static constexpr std::size_t kMaxWindow = 32;

  // `window` = fused poses kept (1..kMaxWindow; 0 disables the test).
  void configure(std::size_t window, float scale_error = 0.0f) {
    window_ = window > kMaxWindow ? kMaxWindow : window;
    scale_error_ = scale_error;
    clear();
  }
  void clear() { count_ = 0; head_ = 0; }
  std::size_t size() const { return count_; }

  // One odometry increment `delta` with its noise `q` (robot frame of the increment), for every kept pose.
  void advance(const Se2f& delta, const Eigen::Matrix3f& q);
  // An odometry step judged faulty by up to (e_xy, e_θ) (the tracker's innovation fault): every kept
  // motion carries that doubt from now on, as the track's covariance does.
  void widen(float exy2, float etheta2);
  // A fused pose with its covariance and map-bias terms (σ_xy, σ_θ as in protection_level.h).
  void push(const Se2f& pose, const Eigen::Matrix3f& cov, float bias_xy_m, float bias_theta_rad);
  // Largest χ² of `pose` (covariance `cov`, bias terms) against the kept poses carried forward by the
  // odometry; 0 when nothing is kept.
  float max_chi2(const Se2f& pose, const Eigen::Matrix3f& cov, float bias_xy_m, float bias_theta_rad) const;

 private:
  struct Kept {
    Se2f pose;
    Eigen::Matrix3f cov;
    float bias_xy2 = 0.0f, bias_theta2 = 0.0f;
    Se2f motion;                     // odometry since this pose, in its robot frame
    Eigen::Matrix3f motion_cov;      // its noise
    float path_m = 0.0f;             // distance the wheels report since this pose
    float turn_rad = 0.0f;           // and the angle they report turned (absolute, accumulated)
  };
  float scale_error_ = 0.0f;
  Kept kept_[kMaxWindow];
  std::size_t window_ = 0, count_ = 0, head_ = 0;  // head_ = next slot to write
};

}  // namespace track
}  // namespace fw
