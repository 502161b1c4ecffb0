#include "sim/common/fail.h"
#include "sim/map/occupancy_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim {
namespace {

enum class BeamKind { kInvalid, kHit, kFreeOnly };

// Classifies a reading and gives the ray length to cast.
BeamKind classify(float r, const PosedScan& s, const OccupancyBuildOptions& o, double* length) {
  if (!std::isfinite(r) || r <= 0.01f) return BeamKind::kInvalid;
  const bool no_return = s.max_range > 0.0f && r >= s.max_range - 0.01f;
  if (no_return) {
    if (!o.free_on_no_return) return BeamKind::kInvalid;
    *length = o.max_usable_range;
    return BeamKind::kFreeOnly;
  }
  if (r > o.max_usable_range) {
    *length = o.max_usable_range;
    return BeamKind::kFreeOnly;
  }
  *length = r;
  return BeamKind::kHit;
}

}  // namespace

bool build_occupancy_grid(const std::vector<PosedScan>& scans, const OccupancyBuildOptions& o, OccupancyGrid* out,
                          OccupancyBuildStats* stats_out, std::string* error) {
  if (!(o.resolution > 0.0) || !std::isfinite(o.resolution)) return fail(error, "map build: resolution must be > 0");
  if (!(o.max_usable_range > 0.0)) return fail(error, "map build: max_usable_range must be > 0");
  if (o.beam_stride == 0) return fail(error, "map build: beam_stride must be ≥ 1");
  if (scans.empty()) return fail(error, "map build: no scans");
  OccupancyBuildStats st;

  // Pass 1: bounds of the scan poses and the beam end points that hit something (rays that only
  // clear free space — beyond max_usable_range or no return — are clipped to these bounds, so long
  // free fans through windows do not inflate the grid).
  double minx = std::numeric_limits<double>::infinity(), miny = minx, maxx = -minx, maxy = -minx;
  auto extend = [&](double x, double y) {
    minx = std::min(minx, x);
    maxx = std::max(maxx, x);
    miny = std::min(miny, y);
    maxy = std::max(maxy, y);
  };
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const PosedScan& s = scans[k];
    if (!std::isfinite(s.pose.x) || !std::isfinite(s.pose.y) || !std::isfinite(s.pose.theta)) {
      return fail(error, "map build: scan " + std::to_string(k) + " has a non-finite pose");
    }
    if (s.ranges == nullptr && s.count > 0) return fail(error, "map build: scan " + std::to_string(k) + " has no ranges");
    extend(s.pose.x, s.pose.y);
    for (std::size_t i = 0; i < s.count; i += o.beam_stride) {
      double len = 0;
      if (classify(s.ranges[i], s, o, &len) != BeamKind::kHit) continue;
      const double a = s.pose.theta + s.angle_min + static_cast<double>(i) * s.angle_increment;
      extend(s.pose.x + len * std::cos(a), s.pose.y + len * std::sin(a));
    }
  }
  const double res = o.resolution;
  const double ox = std::floor((minx - o.margin) / res) * res;
  const double oy = std::floor((miny - o.margin) / res) * res;
  const double w_d = std::ceil((maxx + o.margin - ox) / res) + 1;
  const double h_d = std::ceil((maxy + o.margin - oy) / res) + 1;
  if (w_d * h_d > static_cast<double>(o.max_cells)) {
    return fail(error, "map build: grid of " + std::to_string(static_cast<long long>(w_d)) + "x" +
                           std::to_string(static_cast<long long>(h_d)) + " cells exceeds max_cells (bad poses or resolution?)");
  }
  OccupancyGrid g;
  g.geometry.resolution = static_cast<float>(res);
  g.geometry.origin_x = static_cast<float>(ox);
  g.geometry.origin_y = static_cast<float>(oy);
  g.geometry.width = static_cast<std::uint32_t>(w_d);
  g.geometry.height = static_cast<std::uint32_t>(h_d);
  const int W = static_cast<int>(g.geometry.width), H = static_cast<int>(g.geometry.height);
  std::vector<float> logodds(g.geometry.cell_count(), 0.0f);
  std::vector<std::uint8_t> visited(g.geometry.cell_count(), 0);

  // Pass 2: ray casting (cells in double precision relative to the grid origin).
  auto cell_of = [&](double x, double y, int* cx, int* cy) {
    *cx = std::clamp(static_cast<int>(std::floor((x - ox) / res)), 0, W - 1);
    *cy = std::clamp(static_cast<int>(std::floor((y - oy) / res)), 0, H - 1);
  };
  for (const PosedScan& s : scans) {
    ++st.scans;
    int x0 = 0, y0 = 0;
    cell_of(s.pose.x, s.pose.y, &x0, &y0);
    for (std::size_t i = 0; i < s.count; i += o.beam_stride) {
      ++st.beams;
      double len = 0;
      const BeamKind kind = classify(s.ranges[i], s, o, &len);
      if (kind == BeamKind::kInvalid) {
        ++st.invalid;
        continue;
      }
      if (kind == BeamKind::kFreeOnly) {
        if (s.max_range > 0.0f && s.ranges[i] >= s.max_range - 0.01f) {
          ++st.no_return;
        } else {
          ++st.truncated;
        }
      } else {
        ++st.hits;
      }
      const double a = s.pose.theta + s.angle_min + static_cast<double>(i) * s.angle_increment;
      double ex = s.pose.x + len * std::cos(a), ey = s.pose.y + len * std::sin(a);
      if (kind == BeamKind::kFreeOnly) {
        // Clip to the grid (the start, a scan pose, is inside): shrink the ray to the first exit.
        const double gx0 = ox, gy0 = oy, gx1 = ox + W * res, gy1 = oy + H * res;
        double t = 1.0;
        const double ddx = ex - s.pose.x, ddy = ey - s.pose.y;
        if (ddx > 0) t = std::min(t, (gx1 - s.pose.x) / ddx);
        if (ddx < 0) t = std::min(t, (gx0 - s.pose.x) / ddx);
        if (ddy > 0) t = std::min(t, (gy1 - s.pose.y) / ddy);
        if (ddy < 0) t = std::min(t, (gy0 - s.pose.y) / ddy);
        t = std::max(0.0, t);
        ex = s.pose.x + t * ddx;
        ey = s.pose.y + t * ddy;
      }
      int x1 = 0, y1 = 0;
      cell_of(ex, ey, &x1, &y1);
      // Bresenham: every cell from (x0,y0) up to but excluding (x1,y1) is free.
      const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
      const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
      int err = dx + dy, x = x0, y = y0;
      while (x != x1 || y != y1) {
        const std::size_t idx = static_cast<std::size_t>(y) * W + x;
        logodds[idx] += o.l_free;
        visited[idx] = 1;
        const int e2 = 2 * err;
        if (e2 >= dy) {
          err += dy;
          x += sx;
        }
        if (e2 <= dx) {
          err += dx;
          y += sy;
        }
      }
      const std::size_t end = static_cast<std::size_t>(y1) * W + x1;
      visited[end] = 1;
      logodds[end] += kind == BeamKind::kHit ? o.l_occ : o.l_free;
    }
  }
  g.cells.assign(g.geometry.cell_count(), 255);
  for (std::size_t i = 0; i < g.cells.size(); ++i) {
    if (!visited[i]) {
      ++st.unknown;
    } else if (logodds[i] > o.occupied_logodds) {
      g.cells[i] = 100;
      ++st.occupied;
    } else {
      g.cells[i] = 0;
      ++st.free;
    }
  }
  if (st.occupied == 0) return fail(error, "map build: no beam hit anything (all readings invalid or beyond range)");
  *out = std::move(g);
  if (stats_out != nullptr) *stats_out = st;
  return true;
}

}  // namespace sim
