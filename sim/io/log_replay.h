// A CARMEN log as the time-ordered stream of HAL messages a robot would deliver: scans
// (hal::LaserScan) and odometry (hal::Odometry) with monotonic nanosecond timestamps, for replay
// through hal/sim (SimLaserSource / SimOdometrySource) or device models.
//
// Time base: ipc_timestamp minus the smallest ipc_timestamp of the log (so t ≥ 0). intel's
// timestamps decrease 631 times (../shared/data/README.md); Order::kSortByTime stably sorts all
// events by time (the README's advice), Order::kFileClampTime keeps file order and clamps each
// time to be ≥ the previous one. Odometry comes from the ODOM records when the log has any, else
// (fr-clinic, mit-killian) from the pose carried in each scan record (CarmenScan::odom), emitted
// just before that scan at the same time. At equal times odometry precedes the scan, so the scan's
// odometry is always available when the scan is polled. hal::LaserScan::scan_id = CarmenScan::index
// (= flaser_index; equal to the position in log.scans unless skip_bad_lines dropped scan lines),
// which maps replay outputs back to scans / reference poses; ReplayEvent::index is the position.
// The corrected logs' timestamps are unusable (README): replay raw logs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "sim/io/carmen_log.h"

namespace sim {

struct ReplayEvent {
  enum class Kind : std::uint8_t { kOdometry, kScan };
  Kind kind = Kind::kScan;
  bool odom_from_scan = false;  // kOdometry taken from log.scans[index].odom (no ODOM records)
  size_t index = 0;             // into log.scans (kScan or odom_from_scan) or log.odom
  std::uint64_t t_ns = 0;
};

struct ReplayOptions {
  enum class Order { kSortByTime, kFileClampTime };
  Order order = Order::kSortByTime;
  bool include_odometry = true;
};

std::vector<ReplayEvent> make_replay_events(const CarmenLog& log, const ReplayOptions& options = {});

// Seconds → nanoseconds for replay clocks, clamped to [0, 9e18] ns (285 years): the reader accepts
// timestamps up to ±1e10 s, and a span of 2e10 s would overflow llround (undefined behaviour).
// NaN gives 0.
std::uint64_t seconds_to_ns(double seconds);

// An odometry message of a pose (and velocities, 0 = unknown) at timestamp_ns.
hal::Odometry odometry_message(const fw::Se2d& pose, double v, double omega, std::uint64_t timestamp_ns);
hal::Odometry to_odometry(const CarmenOdom& odom, std::uint64_t timestamp_ns);
hal::Odometry to_odometry(const CarmenScan& scan, std::uint64_t timestamp_ns);  // the scan's odom pose
// Message of one event (kind must match).
hal::LaserScan event_scan(const CarmenLog& log, const ReplayEvent& e);
hal::Odometry event_odometry(const CarmenLog& log, const ReplayEvent& e);

}  // namespace sim
