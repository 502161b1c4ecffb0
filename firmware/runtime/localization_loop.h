// LocalizationLoop: the firmware's main cycle over the HAL. Each spin_once() drains pending
// odometry into a short history, takes the next scan, pairs it with the odometry pose interpolated
// to the scan's timestamp (odometry_interpolation.h), runs Localizer::step and publishes the
// PoseEstimate and a Health frame. Every stage is timed by a PerfCounter. Nothing is allocated:
// the odometry history is a fixed ring and the pending scan a member.
//
// Pairing policy (bad luck is a counter, not a crash):
//  - odometry samples that are not finite or go back in time are rejected (odom_rejected);
//  - a scan with a malformed header (beam_count 0 or > kMaxBeams, non-finite angles) is dropped;
//  - a scan newer than the newest odometry waits for odometry up to `odom_wait_ns` of clock time,
//    then is paired with the newest odometry held constant if that is at most `max_odom_gap_ns`
//    older (a timeout), else dropped;
//  - a scan older than the oldest kept odometry is paired with it when within `max_odom_gap_ns`,
//    else dropped.
//
// Laser silence (`laser_timeout_ns`, 0 = off; mmlfw's config key laser_timeout_ms): when no usable
// scan arrived for that long (since init or the last one), the fault `laser-timeout`
// (hal::HealthFault) is set in health().fault_bits, counted in timeouts, logged, and a pose with
// status `fault` is published (the last pose flagged, so a robot reading POSE frames only does
// not keep trusting it) followed by a health frame; the next usable scan clears the fault. The
// laser source's own faults (laser-disconnected) and invalid-scan count reach health() as well.
#pragma once

#include <cstdint>

#include "firmware/base/perf_counter.h"
#include "firmware/base/ring_buffer.h"
#include "firmware/base/status.h"
#include "firmware/runtime/command_handler.h"
#include "firmware/runtime/localizer.h"
#include "hal/hal.h"

namespace fw {

struct LocalizationLoopOptions {
  std::uint64_t odom_wait_ns = 200'000'000;     // how long a scan may wait for bracketing odometry
  std::uint64_t max_odom_gap_ns = 500'000'000;  // largest gap bridged by holding an odometry sample
  std::uint64_t step_deadline_ns = 0;           // Localizer::step longer than this counts a miss (0 = off)
  std::uint64_t laser_timeout_ns = 0;           // no usable scan for this long: laser-timeout (0 = off)
  // Two consecutive odometry samples farther apart than this are a discontinuity (a jump or a reset
  // of the wheel odometry, not motion: odometry comes at ≥ 10 Hz): a scan between them is paired with
  // the nearer sample, never an interpolation across the jump.
  float max_odom_sample_step_m = 1.0f;
  float max_odom_sample_step_rad = 1.0f;
  // Clock for the perf counters. The simulator steps hal.clock (deterministic time domain) and
  // measures with a real monotonic clock here; nullptr = hal.clock.
  const hal::Clock* perf_clock = nullptr;

  Status validate() const;
};

// Loop-level counters beyond what hal::Health carries.
struct LoopCounters {
  std::uint64_t odom_received = 0;
  std::uint64_t odom_rejected = 0;   // non-finite or out of order
  std::uint64_t scans_received = 0;
  std::uint64_t scans_malformed = 0;
  std::uint64_t scans_unpaired = 0;  // no odometry within max_odom_gap_ns
  std::uint64_t scans_out_of_order = 0;  // taken before the last processed scan (dropped)
  std::uint64_t odom_discontinuities = 0;  // scans between two odometry samples a jump apart (held)
  std::uint64_t scans_interpolated = 0;
  std::uint64_t scans_held = 0;      // paired with a held (not bracketing) odometry sample
  std::uint64_t step_errors = 0;
  std::uint64_t laser_timeouts = 0;  // laser-timeout episodes (each also one health timeout)
};

class LocalizationLoop {
 public:
  static constexpr std::size_t kOdomHistory = 128;

  LocalizationLoop() = default;
  LocalizationLoop(const LocalizationLoop&) = delete;
  LocalizationLoop& operator=(const LocalizationLoop&) = delete;

  // hal.clock, hal.laser, hal.odometry and hal.pose_sink are required; hal.log is optional.
  Status init(hal::Hal& hal, Localizer& localizer, const LocalizationLoopOptions& options = {});
  // One cycle; returns the localizer's error if its step failed (the estimate is then published
  // with status `fault`). Use stepped() to know whether an estimate was produced.
  Status spin_once();
  // Forgets odometry history, the pending scan and the localizer state (kidnapping / restart).
  void reset();
  // Operator commands (hal.commands): carried out at the start of every spin_once, before the scan
  // (command_handler.h). Null = commands are not read.
  void set_command_handler(CommandHandler* handler) { commands_ = handler; }
  // SELECT_MAP of another map (command_handler.h): the next steps go to that map's localizer. The
  // odometry history stays (the wheels are the same robot on every floor); the pending scan too.
  void set_localizer(Localizer& localizer) { localizer_ = &localizer; }

  bool stepped() const { return stepped_; }
  // True while a scan waits for odometry.
  bool scan_pending() const { return has_pending_; }
  const hal::PoseEstimate& last_estimate() const { return estimate_; }
  // Odometry paired with the last processed scan.
  const hal::Odometry& last_odometry() const { return paired_odom_; }
  // Counters and fault bits as published; also refreshed by every spin_once() without a scan,
  // so a heartbeat sent between scans carries the current faults.
  const hal::Health& health() const { return health_; }
  bool laser_timed_out() const { return laser_timed_out_; }
  const LoopCounters& counters() const { return counters_; }

  const PerfCounter& perf_poll() const { return perf_poll_; }
  const PerfCounter& perf_pair() const { return perf_pair_; }
  const PerfCounter& perf_step() const { return perf_step_; }
  const PerfCounter& perf_publish() const { return perf_publish_; }
  const PerfCounter& perf_total() const { return perf_total_; }
  // Time of the last Localizer::step in ns of the perf clock.
  std::uint64_t last_step_ns() const { return last_step_ns_; }

 private:
  enum class Pairing { kWait, kPaired, kDropped };
  void drain_odometry();
  bool validate_scan(const hal::LaserScan& scan);
  bool in_time_order(const hal::LaserScan& scan);
  bool odometry_discontinuous(const hal::Odometry& a, const hal::Odometry& b) const;
  static float angle_diff_rad(float a, float b);
  Pairing pair(std::uint64_t now, hal::Odometry* out);
  void refresh_health(std::uint64_t now);
  void check_laser_silence(std::uint64_t now);
  void log(hal::LogLevel level, const char* fmt, ...) __attribute__((format(printf, 3, 4)));

  hal::Hal* hal_ = nullptr;
  Localizer* localizer_ = nullptr;
  CommandHandler* commands_ = nullptr;
  LocalizationLoopOptions options_;
  const hal::Clock* perf_clock_ = nullptr;

  RingBuffer<hal::Odometry, kOdomHistory> odom_;
  hal::LaserScan pending_;
  bool has_pending_ = false;
  bool stepped_ = false;
  hal::Odometry paired_odom_;
  hal::PoseEstimate estimate_;
  hal::Health health_;
  std::uint32_t loop_dropped_scans_ = 0;
  std::uint64_t last_stepped_scan_ns_ = 0;  // timestamp of the last scan given to the localizer
  bool have_stepped_scan_ = false;  // malformed or unpaired; health_.dropped_scans adds the source's skips
  LoopCounters counters_;
  std::uint64_t last_step_ns_ = 0;
  std::uint64_t last_scan_ns_ = 0;  // clock time of the last usable scan (or of init)
  bool laser_timed_out_ = false;
  bool published_ = false;          // an estimate went out (a timeout then publishes `fault`)

  PerfCounter perf_poll_{"loop.poll"};
  PerfCounter perf_pair_{"loop.pair"};
  PerfCounter perf_step_{"loop.step"};
  PerfCounter perf_publish_{"loop.publish"};
  PerfCounter perf_total_{"loop.total"};
};

}  // namespace fw
