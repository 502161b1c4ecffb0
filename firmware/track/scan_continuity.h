// Scan continuity: how much of this scan the previous one explains, carried by the wheels' increment
// between them — the map-free form of the tracker's "the map must explain most of what the laser
// sees" (TrackOptions::min_explained_fraction). A robot that drives on sees mostly what it saw a scan
// ago; one carried elsewhere between two scans does not, whatever the map says. TrackedLocalizer uses
// it to tell a robot that drove out of the map (its wheels still say where it is) from one carried
// off from a place at the map's edge (dead_reckoning.h). Extension of the dissertation.
//
// Beam-wise, as a z-buffer: the previous end-points, moved into this scan's frame, are binned by
// bearing (kBins over the full turn) keeping the nearest range; an end-point of this scan is
// explained when a bin at most one away holds a range within `tolerance_m` of its own. O(n), no
// heap, no map.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/grid_geometry.h"

namespace fw {
namespace track {

class ScanContinuity {
 public:
  static constexpr std::size_t kBins = 720;  // 0.5° bins
  // Fraction of `cur` (sensor frame, this scan) explained by `prev` (sensor frame, the previous
  // scan), `motion` = the sensor's motion from the previous scan to this one (prev ⊖ cur poses).
  // 1 when `cur` is empty (nothing unexplained); 0 when `prev` is empty.
  float explained_fraction(const Point2f* prev, std::size_t n_prev, const Point2f* cur, std::size_t n_cur,
                           const Se2f& motion, float tolerance_m);
  // The best fraction over the increments the wheels allow: `motion` moved by up to 2σ (sigma_xy_m
  // on x and y, sigma_theta_rad on θ; the tracker's odometry noise model for that increment). The
  // wheels' increment is itself uncertain, and a turn off by 4° moves a wall 10 m away by 0.7 m,
  // past any tolerance: a robot that drove on has some increment within its wheels' bound that
  // explains the scan, a carried one has none (issue 56: the corpus's noisy wheels — 4 cm / 4° a
  // step — made right tracks look carried). 7 turns × 5 shifts, the wheels' own increment first.
  float explained_fraction_within(const Point2f* prev, std::size_t n_prev, const Point2f* cur, std::size_t n_cur,
                                  const Se2f& motion, float sigma_xy_m, float sigma_theta_rad, float tolerance_m);

 private:
  float nearest_[kBins];
};

}  // namespace track
}  // namespace fw
