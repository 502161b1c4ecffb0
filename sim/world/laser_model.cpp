#include "sim/world/laser_model.h"

#include <cmath>

#include "sim/world/ray_cast.h"

namespace sim {

std::string LaserModelOptions::validate() const {
  if (beams < 2 || beams > static_cast<int>(hal::LaserScan::kMaxBeams)) {
    return "laser beams " + std::to_string(beams) + " outside [2, " + std::to_string(hal::LaserScan::kMaxBeams) + "]";
  }
  if (!(fov_deg > 0 && fov_deg <= 360)) return "laser fov_deg " + std::to_string(fov_deg) + " outside (0, 360]";
  if (!(max_range > 0 && std::isfinite(max_range))) return "laser max_range must be a positive number";
  if (!(min_range >= 0 && min_range < max_range)) return "laser min_range must be in [0, max_range)";
  if (!(sigma_range >= 0 && std::isfinite(sigma_range))) return "laser sigma_range must be ≥ 0";
  if (!(dropout_rate >= 0 && dropout_rate <= 1)) return "laser dropout_rate must be in [0, 1]";
  return {};
}

void simulate_scan(const World& world, const fw::Se2d& sensor_pose, double t_s, const LaserModelOptions& opt,
                   fw::RandomStream* rng, hal::LaserScan* out) {
  const double fov = opt.fov_deg * M_PI / 180.0;
  const double inc = opt.beams > 1 ? fov / (opt.beams - 1) : 0.0;
  out->beam_count = static_cast<std::uint32_t>(opt.beams);
  out->angle_min = static_cast<float>(-fov / 2);
  out->angle_increment = static_cast<float>(inc);
  out->range_min = static_cast<float>(opt.min_range);
  out->range_max = static_cast<float>(opt.max_range);
  const Vec2 origin(sensor_pose.x, sensor_pose.y);
  for (int i = 0; i < opt.beams; ++i) {
    const double a = sensor_pose.theta - fov / 2 + i * inc;
    const RayHit h = cast_ray(world, origin, a, opt.max_range, t_s, opt.people_visible);
    // Draw noise and dropout for every beam so the stream position does not depend on geometry.
    const double noise = rng->gaussian() * opt.sigma_range;
    const bool drop = rng->uniform01() < opt.dropout_rate;
    double r = opt.max_range;
    if (h.hit && !drop) {
      r = h.range + noise;
      if (r >= opt.max_range) r = opt.max_range - 1e-3;  // still an echo
      if (r < opt.min_range) r = opt.min_range;
    }
    out->ranges[i] = static_cast<float>(r);
  }
}

}  // namespace sim
