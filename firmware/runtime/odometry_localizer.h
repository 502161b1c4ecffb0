// OdometryLocalizer: the pass-through Localizer used until a matcher is wired (and as the
// dead-reckoning baseline): pose = initial_pose ⊕ ((⊖odom₀) ⊕ odom_t), i.e. odometry relative to
// the first pose it saw. It never claims to know where it is: status is always `searching`.
// Its covariance grows with the motion (Eq. 3.4) so consumers see how little it is worth.
#pragma once

#include "firmware/base/se2.h"
#include "firmware/runtime/localizer.h"

namespace fw {

struct OdometryLocalizerOptions {
  // Map-frame pose reported for the first odometry sample (identity: "where I was switched on").
  Se2f initial_pose;
  // Motion noise per step (standard deviations): translation ∝ distance, rotation ∝ |Δθ| and
  // distance. Used only to grow the reported covariance.
  float sigma_trans_per_m = 0.1f;
  float sigma_rot_per_rad = 0.1f;
  float sigma_rot_per_m = 0.05f;

  Status validate() const;
};

class OdometryLocalizer final : public Localizer {
 public:
  OdometryLocalizer() = default;
  explicit OdometryLocalizer(const OdometryLocalizerOptions& options) : options_(options) {}

  const char* name() const override { return "odom"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

 private:
  OdometryLocalizerOptions options_;
  bool has_first_ = false;
  Se2f first_odom_;
  Se2f last_odom_;
  PoseWithCovariance<float> pose_;
};

}  // namespace fw
