#include "sim/eval/mml_eval/reference_map_check.h"

#include <cmath>
#include <vector>

namespace sim::mmleval {

namespace {

// End-points with distance ≤ inlier_m to an occupied cell (cell lookup of the exact EDT). The count
// is exact when it reaches `need`; below it the loop stops as soon as the points left cannot make
// up the difference and returns some count < need (the search skips those poses anyway: 4–5× fewer
// look-ups, the same poses chosen).
std::size_t count_inliers(const fw::GlobalMap& map, const std::vector<fw::Point2f>& pts, double x, double y, double th,
                          float inlier_m, std::size_t need = 0) {
  const double c = std::cos(th), s = std::sin(th);
  std::size_t n = 0, left = pts.size();
  for (const fw::Point2f& p : pts) {
    if (n + left < need) return n;
    --left;
    const float wx = static_cast<float>(x + c * p.x() - s * p.y()), wy = static_cast<float>(y + s * p.x() + c * p.y());
    if (map.distance_at(wx, wy, 1e9f) <= inlier_m) ++n;
  }
  return n;
}

bool beyond(double err_m, double err_ang, double limit_m, double limit_ang) {
  return (limit_m > 0 && err_m > limit_m) || (limit_ang > 0 && err_ang > limit_ang);
}
}  // namespace

bool beyond_reference(const JudgedError& e, double limit_m, double limit_ang) {
  // A missing limit stays missing: the bound widens only a limit there is.
  return beyond(e.ref_m, e.ref_ang, limit_m > 0 ? limit_m + e.bound_m : 0, limit_ang > 0 ? limit_ang + e.bound_ang : 0);
}

bool judged_beyond(const JudgedError& e, double limit_m, double limit_ang) {
  if (!beyond_reference(e, limit_m, limit_ang)) return false;
  return !e.map_improves || beyond(e.map_m, e.map_ang, limit_m, limit_ang);
}

CarmenScan carmen_scan_of(const hal::LaserScan& scan) {
  CarmenScan c;
  c.angle_min = scan.angle_min;
  c.angle_increment = scan.angle_increment;
  c.max_range = scan.range_max;
  c.ranges.assign(scan.ranges, scan.ranges + scan.beam_count);
  return c;
}

ReferenceMapFit check_reference_against_map(const fw::GlobalMap& map, const CarmenScan& scan, const fw::Se2d& reference,
                                            const ReferenceMapCheckOptions& opt) {
  ReferenceMapFit out;
  out.best = reference;
  std::vector<fw::Point2f> all;
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const float r = scan.ranges[k];
    if (!std::isfinite(r) || r <= 0.05f || r >= scan.max_range || r > opt.max_range_m) continue;
    const float a = scan.angle_min + static_cast<float>(k) * scan.angle_increment;
    all.push_back(fw::Point2f(r * std::cos(a), r * std::sin(a)));
  }
  std::vector<fw::Point2f> pts;
  const std::size_t stride = all.size() > opt.max_points ? (all.size() + opt.max_points - 1) / opt.max_points : 1;
  for (std::size_t k = 0; k < all.size(); k += stride) pts.push_back(all[k]);
  out.points = pts.size();
  if (pts.empty()) return out;
  const float tol = static_cast<float>(opt.inlier_m);
  out.inliers_reference = count_inliers(map, pts, reference.x, reference.y, reference.theta, tol);
  out.inliers_best = out.inliers_reference;
  // Coarse grid over the whole window, then a fine grid around the coarse optimum. The reference wins
  // every tie, and among equally good poses the one nearest the reference is kept: along a corridor
  // every position explains the same end-points, and taking the first of them in scan order moved a
  // reference whose heading alone was off (mit-killian scan 5819: 6° off) 0.3 m along the corridor
  // to the window's edge — the map's pose must move the reference no further than the map asks.
  auto moved = [&](double x, double y, double th) {
    const double dx = x - reference.x, dy = y - reference.y;
    const double dl = opt.lever_m * fw::wrap_angle(th - reference.theta);
    return dx * dx + dy * dy + dl * dl;
  };
  double best_moved = 0.0;
  auto search = [&](const fw::Se2d& c, double half_m, double step_m, double half_rad, double step_rad) {
    const int nt = static_cast<int>(std::lround(half_rad / step_rad));
    const int nx = static_cast<int>(std::lround(half_m / step_m));
    for (int it = -nt; it <= nt; ++it)
      for (int ix = -nx; ix <= nx; ++ix)
        for (int iy = -nx; iy <= nx; ++iy) {
          const double x = c.x + ix * step_m, y = c.y + iy * step_m, th = c.theta + it * step_rad;
          const std::size_t n = count_inliers(map, pts, x, y, th, tol, out.inliers_best);
          if (n < out.inliers_best) continue;
          const double m = moved(x, y, th);
          if (n > out.inliers_best || m < best_moved) {
            out.inliers_best = n;
            out.best = fw::Se2d(x, y, th);
            best_moved = m;
          }
        }
  };
  search(reference, opt.half_window_m, opt.coarse_step_m, opt.half_window_rad, opt.coarse_step_rad);
  const fw::Se2d coarse = out.best;
  search(coarse, opt.coarse_step_m, opt.fine_step_m, opt.coarse_step_rad, opt.fine_step_rad);
  const double gain_needed =
      std::fmax(static_cast<double>(opt.min_gain_points), opt.min_gain_fraction * static_cast<double>(out.points));
  out.improves = static_cast<double>(out.inliers_best) >= static_cast<double>(out.inliers_reference) + gain_needed;
  if (!out.improves) out.best = reference;
  return out;
}

}  // namespace sim::mmleval
