// Is the robot in an unmapped area at this scan? An evaluation rule (not a localizer guard), shared
// by mml-eval and mml-sim: availability is counted over the steps after the first fix "steps inside
// an unmapped area excluded" (issue 11), and on a real log nobody drew the unmapped areas.
//
// The rule asks the map what it says about the scan at the reference pose, with the tracker's own
// outside-map test (firmware/track/pose_tracker.cpp, judge_scan): an end-point is unmapped when it
// lies on an unknown cell (or off the grid) and farther than `wall_m` (the tracker's outlier
// distance) from every mapped wall; the scan is in an unmapped area when more than `max_fraction` of
// its end-points are. There a right localizer must say `outside-map` (the product's definition), so
// such a step is no evidence on availability either way. Judged at the reference, never at the
// estimate: a wrong estimate cannot excuse itself. The steps left out are counted and reported.
//
// Where this matters: fr-clinic has no corrected log, and its map is built from the 1316 scans the
// relations give poses for, so the rooms its corridors open onto are partly unknown in the map
// although the robot saw into them.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "sim/io/carmen_log.h"

namespace sim::mmleval {

struct UnmappedScanOptions {
  float wall_m = 0.30f;        // = TrackOptions::align.outlier_m
  float max_range_m = 30.0f;   // = TrackOptions::align.max_range_m
  float max_fraction = 0.5f;   // = TrackOptions::outside_map_fraction
};

struct UnmappedScan {
  std::size_t points = 0;    // end-points within range
  std::size_t unmapped = 0;  // of them on unknown space, far from every wall
  std::size_t explained = 0; // of them within wall_m of a mapped wall
  double fraction() const { return points ? static_cast<double>(unmapped) / static_cast<double>(points) : 0.0; }
  double explained_fraction() const { return points ? static_cast<double>(explained) / static_cast<double>(points) : 0.0; }
};

UnmappedScan unmapped_scan(const fw::GlobalMap& map, const CarmenScan& scan, const fw::Se2d& pose,
                           const UnmappedScanOptions& opt = {});

// More than opt.max_fraction of the end-points unmapped (a scan without end-points is not).
bool in_unmapped_area(const UnmappedScan& u, const UnmappedScanOptions& opt = {});

// Shown, never used to leave a step out: the map explains less than half of the scan at the
// reference pose although the scan is not unmapped there — the reference (or the map) is off at this
// scan, so no localizer can both be right and fit the map here. On fr-clinic, whose reference between
// the 1316 scans of its relations is chained odometry at 1.6 Hz, 7 % of the steps of a whole run
// (the fast turn at scans 4733–4763: 5–25 % explained); on intel, fr079 and aces none.
bool reference_off_map(const UnmappedScan& u, const UnmappedScanOptions& opt = {});

}  // namespace sim::mmleval
