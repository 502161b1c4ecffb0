// Laser model of a SICK LMS 200 class scanner (Sec. 5.7.1): 180° field of view with 181 (1°) or
// 361 (0.5°) beams, maximum range 8 m (the experiments' useful range) or 80 m, Gaussian range
// noise (σ = 5 mm in the dissertation's simulation) and random "no return" dropouts reported as
// range_max (what the LMS 200 and CARMEN logs report for a missing echo).
//
// Extensions for the sensor profiles of issue 55 (sensor_profiles.h), each off by default so that a
// default scan is bit for bit what it was: range-proportional noise, the sensor's range resolution,
// glass panes (World::glass), reflectivity-limited dropouts towards the maximum range, and sensors
// that measure at irregular angles (RPLIDAR), resampled onto the regular grid of hal::LaserScan as
// their driver does. A 360° field of view spaces its beams by 360°/beams (no beam twice).
#pragma once

#include <cstdint>
#include <string>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "hal/msg/laser_scan.h"
#include "sim/world/ray_cast.h"
#include "sim/world/world.h"

namespace sim {

struct LaserModelOptions {
  int beams = 361;
  double fov_deg = 180.0;      // < 360: beams span it end to end (fov/(beams−1)); 360: fov/beams
  double max_range = 8.0;      // m
  double min_range = 0.02;     // m
  double sigma_range = 0.005;  // m
  double dropout_rate = 0.01;  // probability of a max-range reading per beam
  bool people_visible = true;

  // ---- issue 55 (all off by default) ----
  // Range noise grows with the range: σ = sigma_range + sigma_range_per_m · r.
  double sigma_range_per_m = 0.0;
  // The sensor's own range resolution: every echo is rounded to a multiple of it (0 = none).
  double range_quantum_m = 0.0;
  // A beam whose first surface is a glass pane returns from the pane with this probability, else
  // from the first surface behind it (no return when there is none): 1 = glass like a wall.
  double glass_return_probability = 1.0;
  // Reflectivity-limited range: beyond far_dropout_from × max_range a hit is lost with a
  // probability that rises linearly to far_dropout_max at max_range (dark surfaces fade first;
  // data sheets give the range at 10 % remission beside the one at 90 %). far_dropout_max 0 = off.
  double far_dropout_from = 1.0;
  double far_dropout_max = 0.0;
  // Irregular angles (a rotating triangulation sensor like the RPLIDAR whose samples are not locked
  // to its index): each beam is measured at its nominal angle plus a Gaussian jitter of
  // angle_jitter_deg, and, with revolution_offset, the whole revolution is shifted by a phase drawn
  // uniformly in [0, 1) angular step. The measured beams are resampled onto the regular grid
  // (laser_model.cpp says how). Both 0/false = every beam at its nominal angle.
  double angle_jitter_deg = 0.0;
  bool revolution_offset = false;

  bool irregular_angles() const { return angle_jitter_deg > 0.0 || revolution_offset; }
  // True when a feature that draws from the second random stream is on.
  bool needs_extra_draws() const {
    return irregular_angles() || (glass_return_probability > 0.0 && glass_return_probability < 1.0) ||
           far_dropout_max > 0.0;
  }
  // Angle between beams (rad): fov/(beams−1), or fov/beams for a full 360° turn.
  double angle_increment() const;

  // Error text naming the bad field, or empty.
  std::string validate() const;
};

// Fills *out (beam 0 at −fov/2, counter-clockwise) for a scanner at `sensor_pose` at time t_s.
// `rng` gives the per-beam noise and dropout draws (two per beam, always, in beam order, as
// before the extensions); `extra_rng` gives every draw of the extensions (glass, far dropouts,
// irregular angles), so `rng` is consumed exactly as before whatever the extensions. With extra_rng
// null and an extension on, a stream is seeded from a copy of `rng` (which is not advanced by it).
// `index` (optional): the world's WorldIndex (ray_cast.h), built once by a caller that casts many
// scans in one world (SyntheticRun); the same answers as without it, faster on large buildings.
void simulate_scan(const World& world, const fw::Se2d& sensor_pose, double t_s, const LaserModelOptions& opt,
                   fw::RandomStream* rng, hal::LaserScan* out, fw::RandomStream* extra_rng = nullptr,
                   const WorldIndex* index = nullptr);

}  // namespace sim
