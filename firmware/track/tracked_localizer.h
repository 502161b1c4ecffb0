// TrackedLocalizer ("mml-track"): the product's localization system. Global mode runs MML (Ch. 5)
// until it reports the pose isolated; that fix must then be confirmed by the tracker on the same
// scan (fit of the scan, protection level within the alert limits) before anything is published as
// `localized`. Tracking mode aligns every scan on the global map from the odometry prediction
// (pose_tracker.h) and publishes the pose with its protection level; when the integrity monitor
// gives the track up (kidnap, divergence, unmapped space) MML restarts with a fresh local map.
// PoseEstimate.mode says which one is active; protection_xy_m / protection_theta_rad are set on
// every `localized` pose. Never allocates in step(); both parts live in static storage.
#pragma once

#include <cstdint>

#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/localizer.h"
#include "firmware/track/pose_tracker.h"

namespace fw {
namespace track {

class TrackedLocalizer final : public Localizer {
 public:
  // `global` must be initialised and outlive this object.
  Status init(const TrackOptions& options, const GlobalMap& map, mml::MmlLocalizer* global);
  const char* name() const override { return "mml-track"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

  bool tracking() const { return tracker_.active(); }
  const PoseTracker& tracker() const { return tracker_; }
  mml::MmlLocalizer* global() { return mml_; }
  const mml::MmlLocalizer* global() const { return mml_; }
  // Since reset: fixes accepted, MML fixes the tracker did not confirm, tracks given up.
  std::uint32_t fixes() const { return fixes_; }
  std::uint32_t fix_rejections() const { return fix_rejections_; }
  std::uint32_t tracks_lost() const { return tracks_lost_; }

 private:
  std::size_t scan_points(const hal::LaserScan& scan);
  void publish_track(const TrackStep& ts, hal::PoseEstimate* out) const;
  mml::MmlLocalizer* mml_ = nullptr;
  PoseTracker tracker_;
  Point2f pts_[hal::LaserScan::kMaxBeams];
  std::uint32_t fixes_ = 0, fix_rejections_ = 0, tracks_lost_ = 0;
};

}  // namespace track
}  // namespace fw
