// Laser model of a SICK LMS 200 class scanner (Sec. 5.7.1): 180° field of view with 181 (1°) or
// 361 (0.5°) beams, maximum range 8 m (the experiments' useful range) or 80 m, Gaussian range
// noise (σ = 5 mm in the dissertation's simulation) and random "no return" dropouts reported as
// range_max (what the LMS 200 and CARMEN logs report for a missing echo).
#pragma once

#include <cstdint>
#include <string>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "hal/msg/laser_scan.h"
#include "sim/world/world.h"

namespace sim {

struct LaserModelOptions {
  int beams = 361;
  double fov_deg = 180.0;
  double max_range = 8.0;      // m
  double min_range = 0.02;     // m
  double sigma_range = 0.005;  // m
  double dropout_rate = 0.01;  // probability of a max-range reading per beam
  bool people_visible = true;

  // Error text naming the bad field, or empty.
  std::string validate() const;
};

// Fills *out (beam 0 at −fov/2, counter-clockwise) for a scanner at `sensor_pose` at time t_s.
void simulate_scan(const World& world, const fw::Se2d& sensor_pose, double t_s, const LaserModelOptions& opt,
                   fw::RandomStream* rng, hal::LaserScan* out);

}  // namespace sim
