#include "sim/io/synthetic_odometry.h"

#include <cmath>

#include "firmware/base/rng.h"

namespace sim {

std::vector<fw::Se2d> synthesize_odometry(const std::vector<fw::Se2d>& reference, std::uint64_t seed) {
  std::vector<fw::Se2d> out;
  if (reference.empty()) return out;
  fw::RandomStream rng(seed, 4242);
  out.push_back(reference[0]);
  for (std::size_t i = 1; i < reference.size(); ++i) {
    const fw::Se2d d = reference[i - 1].between(reference[i]);
    const double ds = std::hypot(d.x, d.y), dth = std::fabs(fw::wrap_angle(d.theta));
    const double st = 0.05 * ds + 0.01 * dth, sr = 0.05 * dth + 0.01 * ds;
    const double nx = st * rng.gaussian(), ny = st * rng.gaussian(), nt = sr * rng.gaussian();
    out.push_back(out.back().compose(fw::Se2d(d.x + nx, d.y + ny, fw::wrap_angle(d.theta + nt))));
  }
  return out;
}

}  // namespace sim
