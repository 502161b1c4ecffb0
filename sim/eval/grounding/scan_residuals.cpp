#include "sim/eval/grounding/scan_residuals.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "firmware/map/edt.h"
#include "sim/eval/grounding/odometry_windows.h"

namespace sim::ground {

MapDistance::MapDistance(const OccupancyGrid& grid, std::uint8_t occupied_at) : geo_(grid.geometry) {
  const std::size_t w = geo_.width, h = geo_.height;
  dist_m_.assign(w * h, fw::kEdtInf);
  for (std::size_t i = 0; i < dist_m_.size() && i < grid.cells.size(); ++i) {
    const std::uint8_t c = grid.cells[i];
    if (c != 255 && c >= occupied_at) {
      dist_m_[i] = 0.0f;
      ++occupied_;
    }
  }
  if (occupied_ == 0 || w == 0 || h == 0) return;
  const std::size_t n = std::max(w, h);
  std::vector<int> v(n);
  std::vector<float> z(n + 1), f(n), d(n);
  const fw::EdtScratch scratch{v.data(), z.data(), f.data(), d.data(), n};
  const std::size_t dims[2] = {h, w};  // rows (y) slowest
  fw::squared_edt<2>(dist_m_.data(), dims, scratch);
  for (float& x : dist_m_) x = std::sqrt(x) * geo_.resolution;
}

double MapDistance::at(double x, double y) const {
  if (occupied_ == 0) return std::numeric_limits<double>::infinity();
  const double res = geo_.resolution;
  // Continuous coordinates of the cell centres' lattice: bilinear between the four nearest centres.
  const double gx = (x - geo_.origin_x) / res - 0.5, gy = (y - geo_.origin_y) / res - 0.5;
  if (!std::isfinite(gx) || !std::isfinite(gy)) return std::numeric_limits<double>::infinity();
  const double wmax = static_cast<double>(geo_.width - 1), hmax = static_cast<double>(geo_.height - 1);
  const double cx = std::clamp(gx, 0.0, wmax), cy = std::clamp(gy, 0.0, hmax);
  // Off the lattice: the distance to its border plus the border's own distance.
  const double outside = std::hypot(gx - cx, gy - cy) * res;
  const std::size_t x0 = static_cast<std::size_t>(std::floor(cx)), y0 = static_cast<std::size_t>(std::floor(cy));
  const std::size_t x1 = std::min<std::size_t>(x0 + 1, geo_.width - 1), y1 = std::min<std::size_t>(y0 + 1, geo_.height - 1);
  const double fx = cx - static_cast<double>(x0), fy = cy - static_cast<double>(y0);
  const std::size_t w = geo_.width;
  const double d00 = dist_m_[y0 * w + x0], d10 = dist_m_[y0 * w + x1];
  const double d01 = dist_m_[y1 * w + x0], d11 = dist_m_[y1 * w + x1];
  const double d = (1 - fy) * ((1 - fx) * d00 + fx * d10) + fy * ((1 - fx) * d01 + fx * d11);
  return d + outside;
}

const std::vector<double>& residual_bin_edges() {
  static const std::vector<double> edges = {0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 1.0};
  return edges;
}

void ResidualSample::add_scan(const MapDistance& map, const fw::Se2d& laser_pose, float angle_min,
                              float angle_increment, float range_min, float range_max, const float* ranges,
                              std::size_t count, const ResidualOptions& opt) {
  ++scans;
  const double c = std::cos(laser_pose.theta), s = std::sin(laser_pose.theta);
  for (std::size_t k = 0; k < count; ++k) {
    const double r = ranges[k];
    if (!(r > range_min) || !(r < range_max) || r > opt.max_range_m) continue;
    const double a = angle_min + static_cast<double>(k) * angle_increment;
    const double lx = r * std::cos(a), ly = r * std::sin(a);
    d.push_back(static_cast<float>(map.at(laser_pose.x + c * lx - s * ly, laser_pose.y + s * lx + c * ly)));
  }
}

ResidualSummary summarize(const ResidualSample& s, const ResidualOptions& opt) {
  ResidualSummary out;
  out.scans = s.scans;
  out.points = s.d.size();
  const std::vector<double> v(s.d.begin(), s.d.end());
  out.p50 = quantile(v, 0.5);
  out.p90 = quantile(v, 0.9);
  out.p99 = quantile(v, 0.99);
  const std::vector<double>& edges = residual_bin_edges();
  out.histogram.assign(edges.size(), 0.0);
  std::size_t beyond = 0;
  for (const double x : v) {
    if (x > opt.unexplained_m) ++beyond;
    const std::size_t b = static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), x) - edges.begin());
    out.histogram[b == 0 ? 0 : b - 1] += 1.0;
  }
  if (!v.empty()) {
    for (double& h : out.histogram) h /= static_cast<double>(v.size());
    out.beyond = static_cast<double>(beyond) / static_cast<double>(v.size());
  }
  return out;
}

}  // namespace sim::ground
