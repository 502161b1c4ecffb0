#include "sim/eval/mml_eval/reference_rest_scatter.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim::mmleval {
namespace {

// Nearest-rank percentile of a non-empty vector (sorted in place).
double nearest_rank(std::vector<double>& v, double p) {
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, k > 0 ? k - 1 : 0)];
}

}  // namespace

RestScatter reference_rest_scatter(const std::vector<fw::Se2d>& reference, const std::vector<fw::Se2d>& odometry,
                                   const RestScatterOptions& opt) {
  RestScatter out;
  std::vector<double> dm, dr;
  const std::size_t n = std::min(reference.size(), odometry.size());
  for (std::size_t i = 1; i < n; ++i) {
    const fw::Se2d o = odometry[i - 1].between(odometry[i]);
    if (!(std::hypot(o.x, o.y) < opt.rest_m && std::fabs(o.theta) < opt.rest_rad)) continue;
    // The robot stood still: the reference's own motion, seen from its first pose, minus the
    // (sub-millimetre) odometry motion.
    const fw::Se2d r = reference[i - 1].between(reference[i]);
    dm.push_back(std::hypot(r.x - o.x, r.y - o.y));
    dr.push_back(std::fabs(fw::wrap_angle(r.theta - o.theta)));
  }
  out.pairs = dm.size();
  if (dm.empty()) {
    out.m_p50 = out.m_p99 = out.rad_p50 = out.rad_p99 = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  out.m_p50 = nearest_rank(dm, 0.5);
  out.m_p99 = nearest_rank(dm, 0.99);
  out.rad_p50 = nearest_rank(dr, 0.5);
  out.rad_p99 = nearest_rank(dr, 0.99);
  return out;
}

}  // namespace sim::mmleval
