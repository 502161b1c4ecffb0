// Drivers of the peers of issue 58 (LaMa's Loc2D, AMCL's core), each doing what its ROS node does
// with a scan and the odometry at that scan, without ROS. Plain types only: bench_peers includes no
// peer header (LaMa needs Eigen with heap allocation, the project's Eigen forbids it), and the peer
// libraries are linked into bench_peers alone (never into the product).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace sim::peers {

struct Pose {
  double x = 0, y = 0, theta = 0;
};

// An occupancy grid as a ROS nav_msgs/OccupancyGrid carries it (what both nodes are given by
// map_server): row-major, row 0 = lowest y, 0 free, 100 occupied, 1..99 scaled, anything else unknown.
struct GridView {
  const std::uint8_t* cells = nullptr;
  std::uint32_t width = 0, height = 0;
  double resolution = 0.05, origin_x = 0, origin_y = 0;
};

// A scan as sensor_msgs/LaserScan (the laser at the robot's origin, as mml-track sees it).
struct ScanView {
  const float* ranges = nullptr;
  std::size_t count = 0;
  double angle_min = 0, angle_increment = 0, range_min = 0.01, range_max = 0;
};

// What the node publishes after a scan: the pose at this scan (map→odom of the last filter update
// composed with this scan's odometry, as the node's tf), and whether the filter was updated.
struct StepOut {
  Pose pose;
  bool updated = false;
};

// LaMa Loc2D driven as iris_lama_ros's loc2d node does (lama_driver.cpp).
class LamaDriver {
 public:
  struct Options {  // the node's defaults (lama_driver.cpp cites them)
    double d_thresh = 0.01, a_thresh = 0.2, l2_max = 0.5;
    std::uint32_t patch_size = 32;
  };
  // `seed`: LaMa's random generator (lama::random, else seeded from std::random_device), used by its
  // global localization only.
  LamaDriver(const GridView& map, const Options& opt, unsigned seed);
  ~LamaDriver();
  void set_pose(const Pose& p);                // /initialpose
  void trigger_global_localization();          // Loc2D::triggerGlobalLocalization
  StepOut step(const ScanView& scan, const Pose& odom);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// AMCL's core driven as amcl_node's laserReceived does (amcl_driver.cpp).
class AmclDriver {
 public:
  struct Options {  // the node's defaults (amcl_driver.cpp cites them)
    int min_particles = 100, max_particles = 5000, max_beams = 30, resample_interval = 2;
    double kld_err = 0.01, kld_z = 0.99, alpha_slow = 0.001, alpha_fast = 0.1;
    double odom_alpha[4] = {0.2, 0.2, 0.2, 0.2};
    double z_hit = 0.95, z_rand = 0.05, sigma_hit = 0.2, likelihood_max_dist = 2.0;
    double update_min_d = 0.2, update_min_a = 3.14159265358979323846 / 6.0;
    double init_cov[3] = {0.25, 0.25, (3.14159265358979323846 / 12.0) * (3.14159265358979323846 / 12.0)};
  };
  AmclDriver(const GridView& map, const Options& opt, long seed);
  ~AmclDriver();
  void set_pose(const Pose& p);          // /initialpose: pf_init with the node's initial covariance
  void global_localization();            // /global_localization: pf_init_model over the free cells
  StepOut step(const ScanView& scan, const Pose& odom);
  int particles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim::peers
