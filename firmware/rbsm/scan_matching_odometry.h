// ScanMatchingOdometry: the front end that turns odometry + scans into poses and a local map
// (what MML consumes, Sec. 5.1.1): per scan, polar → points, initial guess = last estimate ⊕
// odometry increment, ScanMatcher::match, then integrate the points at the matched pose and hand
// the newly occupied cells to the LocalMap (fragments). Works with any ScanMatcher (RBSM, ICP).
// Optional update thresholds skip matching while the robot stands still (pose follows odometry).
#pragma once

#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/local_map/local_map.h"
#include "firmware/rbsm/scan_matcher.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"

namespace fw {

struct ScanMatchingOdometryOptions {
  ScanPointsOptions scan;            // range limit / beam stride for scan_to_points
  float min_translation_m = 0.0f;    // match only after this much odometry translation …
  float min_rotation_rad = 0.0f;     // … or rotation since the last match (0, 0: every scan)
  // A matcher that refines its estimate (RBSM's extension of Alg. 1) reports the refined pose; the
  // chain — the next prediction, the map insertion and the local map — stays on Alg. 1's x̂_t unless
  // this is set. Measured (issue 15): chaining on the refined pose made RBSM lose the loop on 1 of
  // 3 intel runs (whole-log 0.095 → 0.48 m) and on aces (0.17 → 0.4–0.5 m); the refinement polishes
  // the output, Alg. 1's robustness keeps the map.
  bool chain_on_refined = false;
  Status validate() const;
};

class ScanMatchingOdometry {
 public:
  // `matcher` must outlive this object; `local_map` may be null.
  Status init(const ScanMatchingOdometryOptions& options, ScanMatcher* matcher, LocalMap* local_map);
  // Starts over at `start` (world frame of the first scan), clearing matcher and local map.
  void reset(const Se2f& start = Se2f());
  // Processes one scan with the odometry pose at its time; *pose receives the estimate.
  // `result` (optional) receives the matcher's report (iterations == 0 when matching was skipped).
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, Se2f* pose, ScanMatchResult* result = nullptr);
  // The reported pose: the chain with the last refinement applied.
  Se2f pose() const { return pose_.compose(correction_); }
  std::uint32_t matches() const { return matches_; }
  std::uint32_t failures() const { return failures_; }

 private:
  ScanMatchingOdometryOptions options_;
  ScanMatcher* matcher_ = nullptr;
  LocalMap* local_map_ = nullptr;
  Point2f points_[hal::LaserScan::kMaxBeams];
  Point2f new_cells_[hal::LaserScan::kMaxBeams];
  bool started_ = false;
  Se2f start_;
  Se2f pose_;        // the chain (Alg. 1's estimate, or the refined one with chain_on_refined)
  Se2f correction_;  // last refinement: chain → reported pose
  Se2f last_odom_;
  Se2f odom_at_match_;
  std::uint32_t matches_ = 0, failures_ = 0;
};

}  // namespace fw
