// A CARMEN log replay prepared as the frames mml-sim feeds to the firmware: per replayed scan, the
// odometry samples before it, the scan, and the ground truth when a reference is given.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "sim/cli/sim_runner.h"

namespace sim {

struct Frame {
  std::uint32_t index = 0;
  double t = 0;
  bool kidnapped = false;
  bool has_truth = false;
  fw::Se2d truth;
  // The reference's own error bound at this scan (sim/io/reference_trajectory.h: 0 where a corrected
  // pose was given, the closure-residual bound between them, inf beyond the last one).
  double truth_bound_m = 0, truth_bound_rad = 0;
  double travelled_m = 0;
  std::vector<hal::Odometry> odometry;
  hal::LaserScan scan;
};

// Odometry records in file order before each scan, plus the scan's own odometry triple
// (FLASER/RLASER/ROBOTLASER1) at the scan time. --start skips the first scans; --kidnap-at jumps to
// another part of the log (the odometry continues with that part's increments, so it sees nothing);
// --odom-noise perturbs every odometry increment. *restamped counts scans whose time stamp stepped
// back. False with *err naming the log, the reference or the bad option.
bool load_log_frames(const SimConfig& cfg, std::vector<Frame>* frames, std::size_t* restamped, std::string* err);

}  // namespace sim
