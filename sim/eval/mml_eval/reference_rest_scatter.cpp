#include "sim/eval/mml_eval/reference_rest_scatter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/eval/mml_eval/mml_eval.h"  // percentile

namespace sim::mmleval {

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
  out.m_p50 = percentile(dm, 50.0);
  out.m_p99 = percentile(dm, 99.0);
  out.rad_p50 = percentile(dr, 50.0);
  out.rad_p99 = percentile(dr, 99.0);
  return out;
}

}  // namespace sim::mmleval
