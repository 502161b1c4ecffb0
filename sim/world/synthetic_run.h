// SyntheticRun: a complete seeded simulated run in a World — route (ground truth), people, noisy
// odometry at its own rate and laser scans — delivered frame by frame in the order a robot's
// drivers would deliver them: for each scan, the odometry samples up to and including the first
// one at or after the scan time, then the scan. Random streams per consumer (fw::RandomStream with
// the run seed): 1 route, 2 odometry, 3 laser, 4 people, 5 the route after a kidnapping, and for the
// issue-55 extensions (drawn only when on) 6 the wheel errors, 7 the laser's glass, far dropouts and
// irregular angles. Same world + options + seed ⇒ identical frames. A sensor's own rate is the
// caller's to set as scan_period_s (sensor_profiles.h gives rate_hz).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/base/rng.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "sim/world/laser_model.h"
#include "sim/world/odometry_model.h"
#include "sim/world/route.h"
#include "sim/world/world.h"

namespace sim {

struct SyntheticRunOptions {
  std::uint64_t seed = 1;
  RouteOptions route;
  LaserModelOptions laser;
  OdometryNoiseOptions odometry;
  double scan_period_s = 0.4;        // one processed scan per 0.3 m at 0.75 m/s
  int odometry_per_scan = 4;         // odometry samples per scan period
  double odometry_phase = 0.37;      // offset of the odometry clock, in odometry periods (≠ 0 ⇒ interpolation)
  int people = -1;                   // moving people; −1 = world default (1 per 150 m² of floor, ≤ 12)
  double people_speed = 0.8;         // m/s
  std::size_t max_scans = 0;         // 0 = the whole route
  // Kidnapping: at this scan index (> 0; 0 = never) the robot is carried to a random route node at
  // least 10 m away and drives on from there; odometry does not see the jump.
  std::size_t kidnap_at_scan = 0;
  std::uint64_t start_time_ns = 1'000'000'000;  // time stamp of t = 0

  std::string validate() const;
};

struct SyntheticFrame {
  std::uint32_t index = 0;
  double t = 0;                       // s since start
  fw::Se2d truth;                     // true robot (= laser) pose at the scan time
  double travelled_m = 0;             // true path length up to this scan (the kidnap jump excluded)
  bool kidnapped = false;             // first scan after the robot was carried away
  std::vector<hal::Odometry> odometry;  // to push before the scan
  hal::LaserScan scan;
};

class SyntheticRun {
 public:
  // Copies the world and adds the people. False with *err naming the bad option.
  bool init(const World& world, const SyntheticRunOptions& opt, std::string* err);
  std::size_t num_scans() const { return num_scans_; }
  // False when the run is over.
  bool next(SyntheticFrame* out);

  const World& world() const { return world_; }
  const RouteTrajectory& trajectory() const { return trajectory_; }
  // Ground truth at time t (s since start), across a kidnapping.
  fw::Se2d truth_at(double t) const;
  // Time of the kidnapping (s), or a negative value.
  double kidnap_time() const { return kidnap_t_; }
  const std::vector<int>& route_nodes() const { return route_nodes_; }
  std::uint64_t time_ns(double t) const;

 private:
  World world_;
  SyntheticRunOptions opt_;
  RouteTrajectory trajectory_;
  RouteTrajectory after_kidnap_;
  double kidnap_t_ = -1;
  bool odom_teleported_ = false;
  std::vector<int> route_nodes_;
  std::size_t num_scans_ = 0;
  std::size_t next_scan_ = 0;
  long long next_odom_ = 0;
  double last_odom_t_ = 0;
  double travelled_ = 0;
  fw::Se2d last_truth_;
  fw::RandomStream laser_rng_;
  fw::RandomStream laser_extra_rng_;
  WorldIndex index_;  // of world_'s walls and glass, built once in init (the people move: not in it)
  OdometrySimulator odom_sim_{OdometryNoiseOptions(), 0};
};

// Adds `count` people walking along straight runs of the route graph (seeded).
void add_people(World* world, int count, double speed, fw::RandomStream* rng);

}  // namespace sim
