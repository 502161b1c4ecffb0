// Device model: a laser scanner + odometry on a CAN bus. Turns a CARMEN log into the frames the
// firmware would see (hal/can message set), with optional deliberate faults, and scores the pose
// frames the firmware sends back against the reference trajectory.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "hal/can_bus.h"
#include "hal_can/codec.h"
#include "sim/io/carmen_log.h"

namespace sim {

struct TimedFrame {
  double t = 0;  // replay time (s), the candump timestamp
  hal::CanFrame frame;
  bool error_frame = false;  // frame.id = error class (CAN_ERR_FLAG added when written)
};

struct CanTrafficOptions {
  bool fd = false;
  size_t first_scan = 0;
  size_t num_scans = 0;       // 0 = to the end of the log
  double speed = 1.0;         // replay time = log time / speed
  double start_time = 1700000000.0;
  // Deliberate faults (0 = off), applied to scan k (counted from first_scan) when k % every == phase.
  size_t corrupt_every = 0;   // flip a range byte in one data segment → CRC error
  size_t drop_every = 0;      // remove one data segment → lost segment
  size_t duplicate_every = 0; // send one data segment twice → duplicate
  size_t bus_off_at = 0;      // before scan k (k >= 1) inject an error-frame burst ...
  size_t bus_off_burst = 0;   // ... of this many bus-off error frames
  // Fault campaign (scripts/bench.sh faults; scan indices k counted from first_scan, 0 = off unless noted):
  size_t invalid_every = 0;   // scan k with k % every == every - 1: range_max 0.01 m, CRC recomputed
                              // (intact on the wire, impossible in content → HEALTH invalid_scans)
  size_t swap_every = 0;      // scans k and k+1 (k % every == every - 1) sent in swapped order
  size_t silence_at = 0;      // from scan k on, no scan for silence_s seconds of log time (odometry goes on)
  double silence_s = 0;
  size_t odom_jump_at = 0;    // odometry from scan k on displaced by odom_jump_m along x
  double odom_jump_m = 0;
  size_t odom_reset_at = 0;   // odometry from scan k on restarts at (0, 0, 0) (a wheel controller reboot)
  size_t time_jump_at = 0;    // sensor clock of scans and odometry from scan k on jumps by time_jump_s
  double time_jump_s = 0;     //   (negative: backwards)
};

struct CanTrafficSummary {
  size_t scans_sent = 0, scans_intact = 0, scans_corrupted = 0, scans_missing_segment = 0, scans_duplicated = 0;
  size_t odometry_sent = 0, frames = 0, error_frames = 0;
  size_t scans_invalid = 0, scans_swapped = 0, scans_silenced = 0;
  double duration_s = 0;        // replay duration
  double sensor_t0 = 0;         // log ipc time that maps to sensor time 1 s
};

// Sensor clock in the frames: µs since (log time of the first scan − 1 s), so it fits the
// protocol's 48-bit field and both scans and odometry share it.
bool build_can_traffic(const CarmenLog& log, const CanTrafficOptions& options, std::vector<TimedFrame>* out,
                       CanTrafficSummary* summary, std::string* error);
bool write_candump_log(const std::string& path, const std::string& iface, const std::vector<TimedFrame>& frames,
                       std::string* error);

struct PoseScoreOptions {
  size_t first_scan = 0, num_scans = 0;  // the scans that were sent (scan_id = index & 0xFFFF)
  double localized_bound_m = 1.0;        // a `localized` pose farther than this from the reference is wrong
  std::FILE* dump = nullptr;             // optional: one line per pose (index status x y ref_x ref_y err)
};

struct PoseScore {
  size_t frames = 0, poses = 0, health = 0, localized = 0, wrong_localized = 0, scored = 0;
  double mean_err_m = 0, max_err_m = 0;               // all poses with a reference (any status)
  double mean_err_localized_m = 0, max_err_localized_m = 0;
  size_t status_counts[5] = {};
  std::vector<std::string> violations;                // protocol violations (human readable)
  hal_can::DecoderStats decoder;
  hal_can::HealthRecord last_health;
  size_t first_localized_scan = 0;                    // scans (from first_scan) until the first `localized`
  size_t fault_updates = 0;  // the last pose repeated with status `fault` (laser-timeout); not in `poses`
  std::uint32_t health_fault_bits_seen = 0;  // OR of the fault bits of every health frame
  size_t health_fault_clears = 0;            // health frames whose fault bits went from set to clear
};

// `reference[i]` = reference pose of log scan i (reference_at_every_scan); may be empty (no error
// figures then). Checks the protocol: pose scan ids belong to sent scans and increase (a repeat of
// the last id with status `fault` is the firmware's laser-timeout, counted in fault_updates), health
// uptime and counters never decrease.
PoseScore score_pose_frames(const std::vector<hal::CanFrame>& frames, const std::vector<fw::Se2d>& reference,
                            const PoseScoreOptions& options);

}  // namespace sim
