// HandoffLocalizer: MML → MCL hand-off (the future work of Sec. 5.8). Global mode runs MML; the
// first `localized` (never `outside-map`) initialises MCL tracking around MML's pose and covariance
// (inflated, floored). Tracking mode runs MCL only (cheap: few particles, likelihood field). When
// the weighted per-beam log-likelihood stays below `collapse_log_likelihood` for `collapse_steps`
// consecutive scans (tracking lost or robot kidnapped), MML restarts with a fresh local map.
// PoseEstimate.mode says which one is active.
#pragma once

#include <cstdint>

#include "firmware/baselines/mcl/mcl_localizer.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/localizer.h"

namespace fw {
namespace mml {

struct HandoffOptions {
  float collapse_log_likelihood = -3.0f;  // per beam (field model with z_rand floor ≈ log(z_rand/max))
  std::uint32_t collapse_steps = 5;       // k
  float init_cov_scale = 4.0f;            // MML's covariance is inflated by this factor …
  float init_sigma_xy_floor_m = 0.10f;    // … and floored
  float init_sigma_theta_floor_rad = 0.05f;
  Status validate() const;
};

class HandoffLocalizer final : public Localizer {
 public:
  // Both localizers must be initialised and outlive this object.
  Status init(const HandoffOptions& options, MmlLocalizer* mml, mcl::MclLocalizer* mcl);
  const char* name() const override { return "handoff"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

  bool tracking() const { return tracking_; }
  std::uint32_t handoffs() const { return handoffs_; }
  std::uint32_t fallbacks() const { return fallbacks_; }

 private:
  HandoffOptions options_;
  MmlLocalizer* mml_ = nullptr;
  mcl::MclLocalizer* mcl_ = nullptr;
  bool tracking_ = false;
  std::uint32_t low_steps_ = 0;
  std::uint32_t handoffs_ = 0, fallbacks_ = 0;
};

}  // namespace mml
}  // namespace fw
