// MclLocalizer: the MCL baseline behind the fw::Localizer seam. reset() spreads the particles
// uniformly over the free map (kidnapped start); status is `localized` once the thesis's
// constraint holds (variance of the best particle's prediction distance over τ steps), else
// `searching`. The Mcl object is large (kMaxParticles): place the localizer in static storage.
// Update gate (MclOptions::update_min_d / update_min_a, as AMCL): a scan is given to the filter only
// once the odometry moved or turned enough since the last update (the first scan after reset() /
// start_tracking() always); otherwise the last estimate moved by the odometry since that update is
// published with the last covariance and status, and the filter is left untouched.
#pragma once

#include <cstdint>

#include "firmware/baselines/mcl/mcl.h"
#include "firmware/runtime/localizer.h"

namespace fw {
namespace mcl {

class MclLocalizer final : public Localizer {
 public:
  Status init(const MclOptions& options, const MapView& map, WorkerPool* pool);
  const char* name() const override { return "mcl"; }
  // Back to exactly the state after init() (filter streams reseeded, counters zero).
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

  // Tracking start (hand-off): particles around pose/cov, status localized from the first step.
  Status start_tracking(const Se2f& pose, const Eigen::Matrix3f& cov, const hal::Odometry& odom);
  // Result of the last filter update (gated scans do not change it).
  const MclStepResult& last() const { return last_; }
  const Mcl& filter() const { return mcl_; }
  // Whether the last step() ran the filter (false: gated, odometry prediction published).
  bool last_step_updated() const { return last_updated_; }
  // Scans gated since init() / reset().
  std::uint64_t gated_steps() const { return gated_steps_; }

 private:
  void publish(const hal::LaserScan& scan, const Se2f& pose, hal::PoseEstimate* out) const;

  Mcl mcl_;
  MclStepResult last_;
  bool have_odom_ = false;
  bool tracking_ = false;
  bool need_uniform_ = true;
  bool force_update_ = true;  // the next scan is used whatever the motion (after reset / start_tracking)
  bool last_updated_ = false;
  std::uint64_t gated_steps_ = 0;
  Se2f prev_odom_;  // odometry pose at the last filter update
};

}  // namespace mcl
}  // namespace fw
