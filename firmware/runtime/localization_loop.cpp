#include "firmware/runtime/localization_loop.h"

#include <cmath>
#include <cstdarg>

#include "firmware/base/fault.h"
#include "firmware/runtime/odometry_interpolation.h"

namespace fw {

Status LocalizationLoopOptions::validate() const {
  if (max_odom_gap_ns == 0) {
    return Status::error(Errc::kInvalidArgument, "LocalizationLoopOptions.max_odom_gap_ns must be > 0");
  }
  return Status::ok();
}

Status LocalizationLoop::init(hal::Hal& hal, Localizer& localizer, const LocalizationLoopOptions& options) {
  if (hal.clock == nullptr || hal.laser == nullptr || hal.odometry == nullptr || hal.pose_sink == nullptr) {
    return Status::error(Errc::kInvalidArgument, "LocalizationLoop::init: HAL lacks %s",
                         hal.clock == nullptr   ? "clock"
                         : hal.laser == nullptr ? "laser source"
                         : hal.odometry == nullptr ? "odometry source"
                                                   : "pose sink");
  }
  FW_RETURN_IF_ERROR(options.validate());
  hal_ = &hal;
  localizer_ = &localizer;
  options_ = options;
  perf_clock_ = options.perf_clock != nullptr ? options.perf_clock : hal.clock;
  odom_.clear();
  has_pending_ = false;
  stepped_ = false;
  counters_ = LoopCounters();
  health_ = hal::Health();
  loop_dropped_scans_ = 0;
  have_stepped_scan_ = false;
  last_stepped_scan_ns_ = 0;
  estimate_ = hal::PoseEstimate();
  last_scan_ns_ = hal.clock->now_ns();
  laser_timed_out_ = false;
  published_ = false;
  return Status::ok();
}

void LocalizationLoop::refresh_health(std::uint64_t now) {
  health_.timestamp_ns = now;
  health_.fault_bits = (fault_bits() & kInternalFaultMask) | (hal_->laser->fault_bits() & hal::kHealthFaultMask) |
                       (laser_timed_out_ ? static_cast<std::uint32_t>(hal::HealthFault::kLaserTimeout) : 0u);
  health_.invalid_scans = hal_->laser->invalid_scans();
  // Scans the source replaced by a newer one before the loop took them are lost too: HEALTH must
  // account for every scan that arrived (a serial SICK stream faster than a slow step skips some).
  health_.dropped_scans = loop_dropped_scans_ + hal_->laser->skipped_scans();
  health_.hint_status = static_cast<std::uint8_t>(localizer_->hint_status());
}

void LocalizationLoop::check_laser_silence(std::uint64_t now) {
  if (options_.laser_timeout_ns == 0 || laser_timed_out_ || now < last_scan_ns_ ||
      now - last_scan_ns_ <= options_.laser_timeout_ns) {
    return;
  }
  laser_timed_out_ = true;
  ++counters_.laser_timeouts;
  ++health_.timeouts;
  refresh_health(now);
  log(hal::LogLevel::kWarning, "laser: no usable scan for %llu ms: fault %s%s",
      static_cast<unsigned long long>((now - last_scan_ns_) / 1000000),
      hal::health_fault_name(hal::HealthFault::kLaserTimeout),
      (health_.fault_bits & static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected)) ? " (laser-disconnected)"
                                                                                                : "");
  if (published_) {
    // The last published pose must not stay the robot's latest word: flag it.
    estimate_.status = hal::LocalizationStatus::kFault;
    estimate_.protection_xy_m = 0.0f;
    estimate_.protection_theta_rad = 0.0f;
    hal_->pose_sink->publish(estimate_);
  }
  hal_->pose_sink->publish_health(health_);
}

void LocalizationLoop::reset() {
  odom_.clear();
  has_pending_ = false;
  have_stepped_scan_ = false;
  stepped_ = false;
  if (localizer_ != nullptr) localizer_->reset();
}

void LocalizationLoop::log(hal::LogLevel level, const char* fmt, ...) {
  if (hal_ == nullptr || hal_->log == nullptr) return;
  va_list args;
  va_start(args, fmt);
  hal_->log->vlog(level, fmt, args);
  va_end(args);
}

void LocalizationLoop::drain_odometry() {
  hal::Odometry o;
  while (hal_->odometry->poll(&o)) {
    ++counters_.odom_received;
    if (!odometry_is_finite(o)) {
      ++counters_.odom_rejected;
      log(hal::LogLevel::kWarning, "odometry t=%llu ns rejected: non-finite value",
          static_cast<unsigned long long>(o.timestamp_ns));
      continue;
    }
    if (!odom_.empty()) {
      const hal::Odometry& newest = odom_.newest();
      if (o.timestamp_ns < newest.timestamp_ns) {
        ++counters_.odom_rejected;
        log(hal::LogLevel::kWarning, "odometry t=%llu ns rejected: older than previous sample t=%llu ns",
            static_cast<unsigned long long>(o.timestamp_ns), static_cast<unsigned long long>(newest.timestamp_ns));
        continue;
      }
      if (o.timestamp_ns == newest.timestamp_ns) {  // duplicate time: the later message wins
        odom_[odom_.size() - 1] = o;
        continue;
      }
    }
    odom_.push_overwrite(o);  // the history is a window: the oldest sample falls out
  }
}

// A scan taken before the last one processed (reordered on the link, e.g. a CAN sender with two
// queues) would make the localizer step back in time and the POSE scan ids go backwards (issue 13
// fault campaign, can_out_of_order): it is dropped and counted. A scan older by more than the
// largest odometry gap is not a reordering but a sensor clock that jumped back; it is accepted so
// that the firmware follows the new clock instead of dropping every scan from then on.
bool LocalizationLoop::in_time_order(const hal::LaserScan& scan) {
  if (!have_stepped_scan_ || scan.timestamp_ns > last_stepped_scan_ns_ ||
      last_stepped_scan_ns_ - scan.timestamp_ns > options_.max_odom_gap_ns) {
    return true;
  }
  ++counters_.scans_out_of_order;
  log(hal::LogLevel::kWarning, "scan %u dropped: taken %llu us before the last processed scan (out of order)",
      scan.scan_id, static_cast<unsigned long long>((last_stepped_scan_ns_ - scan.timestamp_ns) / 1000));
  return false;
}

float LocalizationLoop::angle_diff_rad(float a, float b) {
  float d = std::fmod(a - b, 6.2831853f);
  if (d > 3.14159265f) d -= 6.2831853f;
  if (d < -3.14159265f) d += 6.2831853f;
  return d;
}

bool LocalizationLoop::odometry_discontinuous(const hal::Odometry& a, const hal::Odometry& b) const {
  return !(std::hypot(b.x - a.x, b.y - a.y) <= options_.max_odom_sample_step_m &&
           std::fabs(angle_diff_rad(b.theta, a.theta)) <= options_.max_odom_sample_step_rad);
}

bool LocalizationLoop::validate_scan(const hal::LaserScan& scan) {
  const bool ok = scan.beam_count > 0 && scan.beam_count <= hal::LaserScan::kMaxBeams &&
                  std::isfinite(scan.angle_min) && std::isfinite(scan.angle_increment) &&
                  std::isfinite(scan.range_max) && scan.range_max > 0.0f;
  if (!ok) {
    ++counters_.scans_malformed;
    log(hal::LogLevel::kWarning, "scan %u dropped: malformed header (beam_count %u, range_max %g)", scan.scan_id,
        scan.beam_count, static_cast<double>(scan.range_max));
  }
  return ok;
}

LocalizationLoop::Pairing LocalizationLoop::pair(std::uint64_t now, hal::Odometry* out) {
  const std::uint64_t t = pending_.timestamp_ns;
  const std::uint64_t waited = now > t ? now - t : 0;
  if (odom_.empty()) {
    if (waited < options_.odom_wait_ns) return Pairing::kWait;
    ++counters_.scans_unpaired;
    ++health_.timeouts;
    log(hal::LogLevel::kWarning, "scan %u dropped: no odometry", pending_.scan_id);
    return Pairing::kDropped;
  }
  const hal::Odometry& oldest = odom_[0];
  const hal::Odometry& newest = odom_.newest();
  if (t > newest.timestamp_ns) {
    if (waited < options_.odom_wait_ns) return Pairing::kWait;
    ++health_.timeouts;
    if (t - newest.timestamp_ns > options_.max_odom_gap_ns) {
      ++counters_.scans_unpaired;
      log(hal::LogLevel::kWarning, "scan %u dropped: newest odometry is %llu ms older", pending_.scan_id,
          static_cast<unsigned long long>((t - newest.timestamp_ns) / 1000000));
      return Pairing::kDropped;
    }
    *out = newest;
    out->timestamp_ns = t;
    ++counters_.scans_held;
    return Pairing::kPaired;
  }
  if (t < oldest.timestamp_ns) {
    if (oldest.timestamp_ns - t > options_.max_odom_gap_ns) {
      ++counters_.scans_unpaired;
      log(hal::LogLevel::kWarning, "scan %u dropped: older than all odometry kept", pending_.scan_id);
      return Pairing::kDropped;
    }
    *out = oldest;
    out->timestamp_ns = t;
    ++counters_.scans_held;
    return Pairing::kPaired;
  }
  // Bracketing pair: the history is sorted by time; search from the newest end (scans are recent).
  std::size_t i = odom_.size() - 1;
  while (i > 0 && odom_[i - 1].timestamp_ns > t) --i;
  // Now odom_[i-1].t ≤ t ≤ odom_[i].t, or i == 0 and t == oldest.t.
  const hal::Odometry& a = i > 0 ? odom_[i - 1] : odom_[0];
  const hal::Odometry& b = odom_[i];
  if (odometry_discontinuous(a, b)) {
    // Issue 13 fault campaign (can_odom_jump): interpolating across a jump of the wheel odometry
    // turned one 3 m jump into 0.9 m + 2.1 m, two increments the tracker found physical, and it
    // published `localized` 3 m off. The sample nearest in time is held instead, so the whole jump
    // reaches the localizer at one scan and is seen for what it is.
    ++counters_.odom_discontinuities;
    log(hal::LogLevel::kWarning, "scan %u: odometry jumps %.2f m / %.2f rad between two samples: not interpolated",
        pending_.scan_id, static_cast<double>(std::hypot(b.x - a.x, b.y - a.y)),
        static_cast<double>(std::fabs(angle_diff_rad(b.theta, a.theta))));
    *out = (t - a.timestamp_ns <= b.timestamp_ns - t) ? a : b;
    out->timestamp_ns = t;
    ++counters_.scans_held;
    return Pairing::kPaired;
  }
  if (!interpolate_odometry(a, b, t, out).is_ok()) {
    raise_fault(Fault::kLogicError);  // the search above guarantees the bracket
    return Pairing::kDropped;
  }
  ++counters_.scans_interpolated;
  return Pairing::kPaired;
}

Status LocalizationLoop::spin_once() {
  if (hal_ == nullptr) return Status::error(Errc::kNotInitialized, "LocalizationLoop::spin_once before init");
  stepped_ = false;
  const std::uint64_t now = hal_->clock->now_ns();
  const std::uint64_t t_start = perf_clock_->now_ns();
  if (commands_ != nullptr) commands_->poll();
  {
    PerfScope scope(perf_poll_, *perf_clock_);
    drain_odometry();
    while (!has_pending_ && hal_->laser->poll(&pending_)) {
      ++counters_.scans_received;
      has_pending_ = validate_scan(pending_) && in_time_order(pending_);
      if (!has_pending_) {
        ++loop_dropped_scans_;
      } else {
        if (laser_timed_out_) {
          log(hal::LogLevel::kInfo, "laser: scans back after %llu ms: %s cleared",
              static_cast<unsigned long long>(now > last_scan_ns_ ? (now - last_scan_ns_) / 1000000 : 0),
              hal::health_fault_name(hal::HealthFault::kLaserTimeout));
        }
        laser_timed_out_ = false;
        last_scan_ns_ = now;
      }
    }
  }
  refresh_health(now);  // a heartbeat between scans carries the current faults
  if (!has_pending_) {
    check_laser_silence(now);
    return Status::ok();
  }

  Pairing pairing;
  {
    PerfScope scope(perf_pair_, *perf_clock_);
    pairing = pair(now, &paired_odom_);
  }
  if (pairing == Pairing::kWait) return Status::ok();
  has_pending_ = false;
  if (pairing == Pairing::kDropped) {
    ++loop_dropped_scans_;
    refresh_health(now);
    return Status::ok();
  }

  Status status;
  last_stepped_scan_ns_ = pending_.timestamp_ns;
  have_stepped_scan_ = true;
  {
    const std::uint64_t t0 = perf_clock_->now_ns();
    status = localizer_->step(pending_, paired_odom_, &estimate_);
    last_step_ns_ = perf_clock_->now_ns() - t0;
    perf_step_.add_ns(last_step_ns_);
    if (options_.step_deadline_ns != 0 && last_step_ns_ > options_.step_deadline_ns) ++health_.deadline_misses;
  }
  if (!status.is_ok()) {
    ++counters_.step_errors;
    estimate_.timestamp_ns = pending_.timestamp_ns;
    estimate_.scan_id = pending_.scan_id;
    estimate_.status = hal::LocalizationStatus::kFault;
    log(hal::LogLevel::kError, "scan %u: %s step failed: %s", pending_.scan_id, localizer_->name(), status.message());
  }
  {
    PerfScope scope(perf_publish_, *perf_clock_);
    ++health_.scans_processed;
    refresh_health(now);
    hal_->pose_sink->publish(estimate_);
    hal_->pose_sink->publish_health(health_);
    published_ = true;
  }
  stepped_ = true;
  perf_total_.add_ns(perf_clock_->now_ns() - t_start);
  return status;
}

}  // namespace fw
