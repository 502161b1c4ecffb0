// Reference checked against the map at one scan (an evaluation rule, not a localizer guard).
//
// The references of the real logs are corrected poses chained with the raw odometry between them
// (sim/io/reference_trajectory.h). Where the odometry sample attached to a scan is out of step with
// the laser (fast in-place turns: aces scan 3718 has an odometry turn of 0.306 rad in 84 ms between
// two scans and 0.056 rad in the next 316 ms), the chained reference is off by several degrees at
// that single scan, and a localizer that is right there is counted as an integrity failure.
//
// The check asks the map for a second reference, independently of any localizer output: a
// brute-force correlative search (no gradient solver — the tracker uses one, so the check must not
// share its failure modes) over a window around the log reference counts scan end-points that land
// within `inlier_m` of an occupied cell. Its best pose is used only when it explains clearly more
// end-points than the log reference (+max(min_gain_points, min_gain_fraction · n); the reference
// wins every tie, so a corridor's flat direction never moves it). The evaluation then counts an
// integrity failure or a protection-level exceedance only when it holds against BOTH references;
// a step where the map's pose clears the estimate is excluded from the error figures, counted and
// listed in the report (never silently). A wrong pose in a look-alike place is far from both
// references (the window is ±0.4 m / ±20° around the log reference), so it is still counted.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "hal/msg/laser_scan.h"
#include "sim/io/carmen_log.h"

namespace sim::mmleval {

struct ReferenceMapCheckOptions {
  double half_window_m = 0.40;      // translational search window (each axis)
  double coarse_step_m = 0.05;      // one cell of the 5 cm maps
  double fine_step_m = 0.0125;
  double half_window_rad = 0.35;    // = 20°
  double coarse_step_rad = 0.0087;  // 0.5°
  double fine_step_rad = 0.0022;    // ≈ 0.125°: an end-point at 20 m moves 4 cm
  double inlier_m = 0.10;           // two cells
  double max_range_m = 30.0;
  std::size_t max_points = 180;     // end-points used (evenly subsampled)
  std::size_t min_gain_points = 3;
  double min_gain_fraction = 0.03;
  // Ties between equally good poses go to the one nearest the reference, a heading change counted
  // as the shift it makes at this distance (m).
  double lever_m = 1.0;
};

struct ReferenceMapFit {
  bool improves = false;            // `best` explains clearly more end-points than the log reference
  fw::Se2d best;                    // best pose of the window (the log reference when !improves)
  std::size_t points = 0;           // end-points used
  std::size_t inliers_reference = 0, inliers_best = 0;
};

ReferenceMapFit check_reference_against_map(const fw::GlobalMap& map, const CarmenScan& scan, const fw::Se2d& reference,
                                            const ReferenceMapCheckOptions& opt = {});

// The judging rule of mml-eval and mml-sim, in one place. An error of a `localized` step counts as
// beyond a limit (the integrity limits, or the step's protection level) only when it is beyond the
// limit plus the log reference's own bound (reference_trajectory.h) AND — where the map's pose
// explains the scan clearly better (`map_improves`, the check above) — beyond the limit against that
// pose too. Angles in one unit of the caller's choice (mml-eval radians, mml-sim degrees); a limit
// component ≤ 0 is no limit (a pose published without that bound).
struct JudgedError {
  double ref_m = 0, ref_ang = 0;      // error against the log reference
  double bound_m = 0, bound_ang = 0;  // the reference's own error bound at this scan
  bool map_improves = false;
  double map_m = 0, map_ang = 0;      // error against the map's pose (read only when map_improves)
};
// Beyond the limit against the log reference plus its bound.
bool beyond_reference(const JudgedError& e, double limit_m, double limit_ang);
// Judged beyond: as above, and not cleared by the map's pose.
bool judged_beyond(const JudgedError& e, double limit_m, double limit_ang);

// The scan a localizer consumed (hal::LaserScan), as the check reads it.
CarmenScan carmen_scan_of(const hal::LaserScan& scan);

}  // namespace sim::mmleval
