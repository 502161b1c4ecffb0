// Localizer: what the runtime loop drives each scan. Implementations: the odometry pass-through
// (until a matcher is wired), MML global localization, MCL, and the MML→MCL hand-off. One scan
// and the odometry pose at its time in, one PoseEstimate out. Implementations allocate nothing in
// step(); all storage is sized in their init from an options struct.
#pragma once

#include "firmware/base/status.h"
#include "hal/msg/command.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "hal/msg/pose_estimate.h"

namespace fw {

class Localizer {
 public:
  virtual ~Localizer() = default;
  virtual const char* name() const = 0;
  // Forget everything (kidnapped / fresh start).
  virtual void reset() = 0;
  // `odom` is the wheel-odometry pose at (or interpolated to) the scan's timestamp.
  virtual Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) = 0;
  // An operator's pose hint (SET_POSE_HINT, already checked: finite, σ > 0, this map). It must be
  // verified by the scans before anything is published `localized` from it (mml-track: as a
  // candidate that passes the checks an MML fix passes). Localizers that cannot take one say so.
  virtual Status set_pose_hint(const hal::PoseHint& hint) {
    (void)hint;
    return Status::error(Errc::kUnsupported, "localizer %s takes no pose hint", name());
  }
  // Where the last hint stands (HEALTH.HintStatus).
  virtual hal::HintStatus hint_status() const { return hal::HintStatus::kNone; }
};

}  // namespace fw
