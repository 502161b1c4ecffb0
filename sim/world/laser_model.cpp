#include "sim/world/laser_model.h"

#include <algorithm>
#include <cmath>

#include "sim/world/ray_cast.h"

namespace sim {

namespace {
bool laser_in_range(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

// The issue-55 fields (every message names its field).
std::string validate_extensions(const LaserModelOptions& o) {
  if (!laser_in_range(o.sigma_range_per_m, 0.0, 1.0)) return "laser sigma_range_per_m must be in [0, 1]";
  if (!laser_in_range(o.range_quantum_m, 0.0, 1.0)) return "laser range_quantum_m must be in [0, 1] m";
  if (o.range_quantum_m >= o.max_range) return "laser range_quantum_m must be below max_range";
  if (!laser_in_range(o.glass_return_probability, 0.0, 1.0)) return "laser glass_return_probability must be in [0, 1]";
  if (!laser_in_range(o.far_dropout_from, 0.0, 1.0)) return "laser far_dropout_from must be in [0, 1] (of max_range)";
  if (!laser_in_range(o.far_dropout_max, 0.0, 1.0)) return "laser far_dropout_max must be in [0, 1]";
  if (o.far_dropout_max > 0.0 && !(o.far_dropout_from < 1.0)) {
    return "laser far_dropout_from must be below 1 when far_dropout_max > 0";
  }
  if (!laser_in_range(o.angle_jitter_deg, 0.0, 10.0)) return "laser angle_jitter_deg must be in [0, 10]";
  return {};
}
}  // namespace

std::string LaserModelOptions::validate() const {
  if (beams < 2 || beams > static_cast<int>(hal::LaserScan::kMaxBeams)) {
    return "laser beams " + std::to_string(beams) + " outside [2, " + std::to_string(hal::LaserScan::kMaxBeams) + "]";
  }
  if (!(fov_deg > 0 && fov_deg <= 360)) return "laser fov_deg " + std::to_string(fov_deg) + " outside (0, 360]";
  if (!(max_range > 0 && std::isfinite(max_range))) return "laser max_range must be a positive number";
  if (!(min_range >= 0 && min_range < max_range)) return "laser min_range must be in [0, max_range)";
  if (!(sigma_range >= 0 && std::isfinite(sigma_range))) return "laser sigma_range must be ≥ 0";
  if (!(dropout_rate >= 0 && dropout_rate <= 1)) return "laser dropout_rate must be in [0, 1]";
  return validate_extensions(*this);
}

double LaserModelOptions::angle_increment() const {
  const double fov = fov_deg * M_PI / 180.0;
  // A full turn: beam `beams` would be beam 0 again, so the step is fov/beams (no beam twice).
  if (fov_deg >= 360.0) return fov / beams;
  return beams > 1 ? fov / (beams - 1) : 0.0;
}

namespace {

// One beam's reading at world angle `a`: the cast, then the two draws of `rng` every beam takes
// (noise, dropout: the stream position does not depend on geometry), then the extensions' draws of
// `extra` (each taken on every beam while its feature is on, for the same reason).
double measure_beam(const World& world, const WorldIndex* index, const Vec2& origin, double a, double t_s,
                    const LaserModelOptions& opt, fw::RandomStream* rng, fw::RandomStream* extra) {
  const RayHit h = index != nullptr ? cast_ray(world, *index, origin, a, opt.max_range, t_s, opt.people_visible)
                                    : cast_ray(world, origin, a, opt.max_range, t_s, opt.people_visible);
  const double g = rng->gaussian();
  const bool drop = rng->uniform01() < opt.dropout_rate;
  bool hit = h.hit;
  double range = h.range;
  const double pg = opt.glass_return_probability;
  if (pg < 1.0) {
    const bool pane = pg > 0.0 && extra->uniform01() < pg;
    if (h.glass && !pane) {  // through the pane: the surface behind, or nothing
      hit = h.behind_hit;
      range = h.behind_range;
    }
  }
  if (opt.far_dropout_max > 0.0) {
    const double u = extra->uniform01();
    const double from = opt.far_dropout_from * opt.max_range;
    if (hit && range > from && u < opt.far_dropout_max * (range - from) / (opt.max_range - from)) hit = false;
  }
  double r = opt.max_range;
  if (hit && !drop) {
    const double sigma =
        opt.sigma_range_per_m > 0.0 ? opt.sigma_range + opt.sigma_range_per_m * range : opt.sigma_range;
    r = range + g * sigma;
    const double q = opt.range_quantum_m;
    if (q > 0.0) r = std::round(r / q) * q;
    if (r >= opt.max_range) {  // still an echo (on the range grid when there is one)
      r = q > 0.0 ? std::floor((opt.max_range - 1e-3) / q) * q : opt.max_range - 1e-3;
    }
    if (r < opt.min_range) r = opt.min_range;
  }
  return r;
}

// Irregular angles. The sensor measures beam k at (k + phase + jitter_k) steps from angle_min; its
// driver hands on a regular grid. We resample as the RPLIDAR ROS driver's angle compensation does
// in spirit (each measurement goes to the grid slot of its angle, a slot nothing fell into is a "no
// return"), but to the NEAREST slot — a measurement lands at most half a step from the angle it is
// reported at — and, when two fall into one slot, the nearer one wins. Chosen over interpolating
// two neighbours because interpolation invents ranges across depth edges (a phantom point between
// a door frame and the wall behind), which no driver reports; chosen over "slot ⌊angle/step⌋" (up
// to a whole step of angle error) because the error bound is then half a step. For a 360° scan the
// slots wrap around; otherwise a measurement outside the grid is dropped.
void simulate_irregular(const World& world, const WorldIndex* index, const fw::Se2d& pose, double t_s,
                        const LaserModelOptions& opt, fw::RandomStream* rng, fw::RandomStream* extra,
                        hal::LaserScan* out) {
  const int n = opt.beams;
  const double fov = opt.fov_deg * M_PI / 180.0;
  const double inc = opt.angle_increment();
  const bool full_turn = opt.fov_deg >= 360.0;
  double best[hal::LaserScan::kMaxBeams];
  for (int j = 0; j < n; ++j) {
    best[j] = 1.0;  // > half a step: empty
    out->ranges[j] = static_cast<float>(opt.max_range);
  }
  const double phase = opt.revolution_offset ? extra->uniform01() - 0.5 : 0.0;
  const double jitter_steps = opt.angle_jitter_deg * M_PI / 180.0 / inc;
  const Vec2 origin(pose.x, pose.y);
  for (int k = 0; k < n; ++k) {
    const double jitter = jitter_steps > 0.0 ? extra->gaussian() * jitter_steps : 0.0;
    const double s = k + phase + jitter;  // measured angle, in steps from angle_min
    const double r = measure_beam(world, index, origin, pose.theta - fov / 2 + s * inc, t_s, opt, rng, extra);
    long j = std::lround(s);
    const double d = std::fabs(s - static_cast<double>(j));
    if (full_turn) {
      j = ((j % n) + n) % n;
    } else if (j < 0 || j >= n) {
      continue;
    }
    if (d < best[j]) {
      best[j] = d;
      out->ranges[j] = static_cast<float>(r);
    }
  }
}

}  // namespace

void simulate_scan(const World& world, const fw::Se2d& sensor_pose, double t_s, const LaserModelOptions& opt,
                   fw::RandomStream* rng, hal::LaserScan* out, fw::RandomStream* extra_rng,
                   const WorldIndex* index) {
  const double fov = opt.fov_deg * M_PI / 180.0;
  const double inc = opt.angle_increment();
  out->beam_count = static_cast<std::uint32_t>(opt.beams);
  out->angle_min = static_cast<float>(-fov / 2);
  out->angle_increment = static_cast<float>(inc);
  out->range_min = static_cast<float>(opt.min_range);
  out->range_max = static_cast<float>(opt.max_range);
  fw::RandomStream local;
  if (extra_rng == nullptr && opt.needs_extra_draws()) {
    // A stream of its own, seeded from a copy of `rng` so `rng` advances exactly as without it.
    fw::RandomStream copy = *rng;
    const std::uint64_t hi = copy.next_u32();
    const std::uint64_t lo = copy.next_u32();
    local.reseed((hi << 32) | lo, 0x4c41534552ULL);
    extra_rng = &local;
  }
  if (opt.irregular_angles()) {
    simulate_irregular(world, index, sensor_pose, t_s, opt, rng, extra_rng, out);
    return;
  }
  const Vec2 origin(sensor_pose.x, sensor_pose.y);
  for (int i = 0; i < opt.beams; ++i) {
    const double a = sensor_pose.theta - fov / 2 + i * inc;
    out->ranges[i] = static_cast<float>(measure_beam(world, index, origin, a, t_s, opt, rng, extra_rng));
  }
}

}  // namespace sim
