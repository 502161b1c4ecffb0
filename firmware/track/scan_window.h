// The global job's window, measured: the time between the sensor context's steps (issue 56 CI,
// the vcan HIL). The global step's result is taken `result_delay_scans` steps after it was offered
// (firmware/track/global_context.h), so the time pRANSAM may use in deadline mode (Sec. 4.4.3) is
// that many scan intervals as the robot sees them, not the constant period of one laser model.
// With the 75 Hz SICK LMS's 13.3 ms assumed for every laser, a 6–10 Hz laser (the HIL replays aces
// at 78 ms a scan) left pRANSAM one round a step after a 4.5 ms front end in a 1-CPU guest, and the
// robot often did not find itself in 250 scans, while 90 % of each window went unused.
//
//  - the median of the last kIntervals intervals: one stalled scan (a laser timeout, a late frame)
//    does not widen the window, and a new rate is followed within kIntervals/2 scans;
//  - at least the context's configured deadline: a sensor context running faster than the fastest
//    laser planned for (an unpaced replay) gives pRANSAM no less than it had; an overrunning job's
//    result is still taken later, moved by odometry, so a longer step costs skipped offers only;
//  - intervals longer than kMaxIntervalNs are a fault (the laser-timeout fault is raised at 0.5 s),
//    not a scan period: left out.
// No heap, no lock: written and read by the sensor context only.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fw {
namespace track {

class ScanWindow {
 public:
  static constexpr std::size_t kIntervals = 8;
  static constexpr std::uint64_t kMaxIntervalNs = 500'000'000;

  // Forget the intervals (a restart): until new ones are seen the window is the configured one.
  void reset() {
    count_ = 0;
    next_ = 0;
    have_last_ = false;
  }
  // One sensor-context step at `now_ns`.
  void step(std::uint64_t now_ns);
  // The median of the kept intervals; 0 before the first one.
  std::uint64_t median_interval_ns() const;
  // The window for a job whose result is taken `delay_scans` steps later: `delay_scans` median
  // intervals, at least `configured_ns`.
  std::uint64_t window_ns(std::uint32_t delay_scans, std::uint64_t configured_ns) const;

 private:
  std::uint64_t intervals_[kIntervals] = {};
  std::size_t count_ = 0, next_ = 0;
  std::uint64_t last_ns_ = 0;
  bool have_last_ = false;
};

}  // namespace track
}  // namespace fw
