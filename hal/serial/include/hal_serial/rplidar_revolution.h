// RplidarRevolution: one RPLIDAR revolution → one hal::LaserScan on a regular angular grid.
// An RPLIDAR measures at angles of its own: the samples of a turn are not locked to the index
// (each turn starts at another phase, the motor's speed wavers: A1 at 5.5 Hz and 2 kHz gives
// about 364 samples ~0.99° apart), while hal::LaserScan, which every algorithm of the firmware
// reads, is a regular grid (angle_min + i·angle_increment). We RESAMPLE rather than carry per-beam
// angles: a per-beam angle array would grow every scan buffer of the firmware (rings, arena
// copies) by 4.3 KB for the sake of one sensor family, and the grid is what RBSM, pRANSAM and the
// tracker are built and measured on. Each sample goes to the NEAREST slot of the grid (the
// simulated rplidar-a1 profile does the same, sim/world/laser_model.cpp), and when two fall into
// one slot the nearer one wins: a measurement is then reported at most half a step from the
// angle it was taken at, and no range is invented between two (interpolating would put phantom
// points between a door frame and the wall behind it). A slot no sample fell into is "no return"
// (range_max). The grid: `beams` slots over 360° from −π (1° for 360 beams, the A1's nominal
// resolution; 720 or more for an A2/A3/S1 in express mode).
// Angles: RPLIDAR angles grow clockwise from the front (protocol document, Fig. "angle and
// distance value geometric definition"); hal::LaserScan's grow counter-clockwise (x forward), so
// a sample at θ goes to −θ. A sample with distance 0 (no measurement) or quality 0 is not placed.
// A revolution ends at the next sample with the start flag; the samples before the first start
// flag (a turn seen only in part) and a turn with fewer than min_samples samples (motor spinning up
// or stalling, data lost) are dropped and counted, never handed out half-empty.
#pragma once

#include <cstdint>

#include "hal/msg/laser_scan.h"
#include "hal_serial/rplidar_protocol.h"

namespace hal_serial {

struct RplidarRevolutionOptions {
  std::uint32_t beams = 360;        // grid slots over 360° (≤ hal::LaserScan::kMaxBeams)
  float range_min_m = 0.15f;        // A1/A2 data sheets: 0.15 m
  float range_max_m = 12.0f;        // A1: 12 m; A2M8 16 m (A2M12 18 m); A3 25 m; S1 40 m
  std::uint32_t min_samples = 100;  // fewer in a turn: a partial revolution, dropped
  std::uint32_t max_samples = 8192; // more without a start flag: the flag was lost, start again
};

struct RplidarRevolutionStats {
  std::uint32_t revolutions = 0;
  std::uint32_t partial = 0;        // turns dropped for too few samples
  std::uint32_t leading = 0;        // samples before the first start flag (a turn seen only in part)
  std::uint32_t overlong = 0;       // turns without a start flag within max_samples
  std::uint32_t samples = 0;        // samples placed on the grid
  std::uint32_t invalid = 0;        // samples without a measurement (distance 0 / quality 0)
  std::uint32_t collisions = 0;     // samples that lost their slot to a nearer one
};

class RplidarRevolution {
 public:
  void init(const RplidarRevolutionOptions& options);
  // Forgets the turn in progress (after a restart: the next start flag begins a fresh turn).
  void reset();
  // Adds a sample received at t_ns. True when it closed a revolution: *out then holds that turn,
  // stamped with the receipt time of its first sample.
  bool add(const RplidarSample& s, std::uint64_t t_ns, hal::LaserScan* out);
  const RplidarRevolutionStats& stats() const { return stats_; }
  const RplidarRevolutionOptions& options() const { return options_; }

 private:
  void begin(std::uint64_t t_ns);
  void place(const RplidarSample& s);

  RplidarRevolutionOptions options_;
  bool started_ = false;
  std::uint32_t count_ = 0;  // samples of the turn in progress
  std::uint64_t t0_ns_ = 0;
  float ranges_[hal::LaserScan::kMaxBeams] = {};
  float best_[hal::LaserScan::kMaxBeams] = {};  // |offset| in slots of the sample kept, > 0.5 = empty
  std::uint32_t next_id_ = 0;
  RplidarRevolutionStats stats_;
};

}  // namespace hal_serial
