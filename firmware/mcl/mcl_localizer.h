// MclLocalizer: the MCL baseline behind the fw::Localizer seam. reset() spreads the particles
// uniformly over the free map (kidnapped start); status is `localized` once the thesis's
// constraint holds (variance of the best particle's prediction distance over τ steps), else
// `searching`. The Mcl object is large (kMaxParticles): place the localizer in static storage.
#pragma once

#include "firmware/mcl/mcl.h"
#include "firmware/runtime/localizer.h"

namespace fw {
namespace mcl {

class MclLocalizer final : public Localizer {
 public:
  Status init(const MclOptions& options, const MapView& map, WorkerPool* pool);
  const char* name() const override { return "mcl"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

  // Tracking start (hand-off): particles around pose/cov, status localized from the first step.
  Status start_tracking(const Se2f& pose, const Eigen::Matrix3f& cov, const hal::Odometry& odom);
  const MclStepResult& last() const { return last_; }
  const Mcl& filter() const { return mcl_; }

 private:
  Mcl mcl_;
  MclStepResult last_;
  bool have_odom_ = false;
  bool tracking_ = false;
  bool need_uniform_ = true;
  Se2f prev_odom_;
};

}  // namespace mcl
}  // namespace fw
