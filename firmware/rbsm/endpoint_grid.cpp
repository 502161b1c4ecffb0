#include "firmware/rbsm/endpoint_grid.h"

#include "firmware/base/memory_report.h"

#include <cmath>
#include <algorithm>
#include <cstring>

namespace fw {

Status EndpointGridOptions::validate() const {
  if (!(resolution > 0.0f) || !std::isfinite(resolution)) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: resolution %g m must be positive",
                         static_cast<double>(resolution));
  }
  if (size_log2 < 4 || size_log2 > 13) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: size_log2 %u outside [4, 13]", size_log2);
  }
  if (subcell_log2 > 3) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: subcell_log2 %u outside [0, 3]", subcell_log2);
  }
  if (size_log2 + subcell_log2 < 6) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: lookup side 2^%u sub-cells below the 64 of a page tile",
                         size_log2 + subcell_log2);
  }
  if (size_log2 + subcell_log2 > 15) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: lookup side 2^%u sub-cells too large (max 2^15)",
                         size_log2 + subcell_log2);
  }
  // ξ > 1.5 cells would need neighbours beyond the 3×3 block (see header).
  if (!(xi_cells > 0.0f) || xi_cells > 1.5f) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: xi %g cells outside (0, 1.5]",
                         static_cast<double>(xi_cells));
  }
  if (!(recenter_fraction > 0.0f) || recenter_fraction > 0.45f) {
    return Status::error(Errc::kInvalidArgument, "endpoint grid: recenter_fraction %g outside (0, 0.45]",
                         static_cast<double>(recenter_fraction));
  }
  return Status::ok();
}

std::size_t EndpointGrid::required_bytes(const EndpointGridOptions& o) {
  const std::size_t side = std::size_t{1} << o.size_log2;
  const std::size_t sub = side << o.subcell_log2;
  return side * side + sub * sub + 256;  // + zero sentinel line + alignment
}

Status EndpointGrid::init(const EndpointGridOptions& options, StartupArena& arena) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  side_ = 1u << options.size_log2;
  cell_mask_ = side_ - 1;
  k_ = 1u << options.subcell_log2;
  sub_shift_ = options.size_log2 + options.subcell_log2;
  sub_mask_ = (1u << sub_shift_) - 1;
  const std::size_t cells = static_cast<std::size_t>(side_) * side_;
  const std::size_t subs = static_cast<std::size_t>(sub_mask_ + 1) * (sub_mask_ + 1);
  Result<void*> occ = arena.allocate(cells, 64, "rbsm endpoint grid");
  if (!occ) return occ.status();
  // One extra line: index `subs` is a permanent zero (LookupView::zero_index) for points outside
  // the window, so the weighting loop needs no branch.
  Result<void*> lut = arena.allocate(subs + 64, 64, "rbsm likelihood lookup");
  if (!lut) return lut.status();
  occupancy_ = static_cast<std::uint8_t*>(*occ);
  lookup_ = static_cast<std::uint8_t*>(*lut);
  std::memset(occupancy_, 0, cells);
  std::memset(lookup_, 0, subs + 64);
  FW_RETURN_IF_ERROR(MemoryReport::instance().add({"rbsm", "end-point grid + likelihood lookup", cells + subs + 64, cells, nullptr}));
  // Eq. 2.9 in cells: δ = exp(−d²) for d ≤ ξ, else 0; quantised to 1/255.
  const float xi2 = options.xi_cells * options.xi_cells;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int n = (dy + 1) * 3 + (dx + 1);
      for (std::uint32_t b = 0; b < k_; ++b) {
        for (std::uint32_t a = 0; a < k_; ++a) {
          const float ux = (static_cast<float>(a) + 0.5f) / static_cast<float>(k_) - 0.5f;
          const float uy = (static_cast<float>(b) + 0.5f) / static_cast<float>(k_) - 0.5f;
          const float ddx = static_cast<float>(dx) - ux, ddy = static_cast<float>(dy) - uy;
          const float d2 = ddx * ddx + ddy * ddy;
          float v = 0.0f;
          if (d2 <= xi2 * (1.0f + 1e-6f)) v = std::exp(-d2) * static_cast<float>(kLikelihoodMax);
          table_[n][b * k_ + a] = static_cast<std::uint8_t>(std::lround(v));
        }
      }
    }
  }
  centered_ = false;
  occupied_count_ = 0;
  dirty_x0_ = dirty_y0_ = 0;
  dirty_x1_ = dirty_y1_ = -1;
  return Status::ok();
}

void EndpointGrid::world_to_cell(float x, float y, std::int32_t* gx, std::int32_t* gy) const {
  *gx = static_cast<std::int32_t>(std::floor(x / options_.resolution));
  *gy = static_cast<std::int32_t>(std::floor(y / options_.resolution));
}

void EndpointGrid::clear_cell(std::int32_t gx, std::int32_t gy) {
  std::uint8_t& c = occupancy_[cell_index(gx, gy)];
  if (c) --occupied_count_;
  c = 0;
  for (std::uint32_t b = 0; b < k_; ++b) {
    const std::uint32_t sy = static_cast<std::uint32_t>(gy) * k_ + b;
    for (std::uint32_t a = 0; a < k_; ++a) {
      lookup_[tiled_index((static_cast<std::uint32_t>(gx) * k_ + a) & sub_mask_, sy & sub_mask_, sub_shift_)] = 0;
    }
  }
}

// The dirty box's occupancy, row by row (a row's run wraps around the toroidal window at most once).
void EndpointGrid::clear_box_rows(std::int64_t w, std::int64_t h) {
  const std::uint32_t cols = w >= side_ ? side_ : static_cast<std::uint32_t>(w);
  const std::uint32_t rows = h >= side_ ? side_ : static_cast<std::uint32_t>(h);
  const std::uint32_t x0 = static_cast<std::uint32_t>(dirty_x0_) & cell_mask_;
  for (std::uint32_t r = 0; r < rows; ++r) {
    std::uint8_t* row = occupancy_ + (static_cast<std::size_t>((static_cast<std::uint32_t>(dirty_y0_) + r) & cell_mask_) << options_.size_log2);
    const std::uint32_t first = cols <= side_ - x0 ? cols : side_ - x0;
    std::memset(row + x0, 0, first);
    if (first < cols) std::memset(row, 0, cols - first);
  }
}

// The lookup's 64 × 64 sub-cell pages (4 KiB, tiled_index) that meet the dirty box and its 1-cell
// border: every raised value lies in that box, so whole pages are zeroed. A reset used to clear
// the box cell by cell (16 scattered bytes each): 14-17 ms for the aces local map, longer than the
// global context's window; the pages take a memset each.
void EndpointGrid::clear_box_tiles() {
  const std::int64_t k = k_;
  const std::int64_t sx0 = (static_cast<std::int64_t>(dirty_x0_) - 1) * k, sx1 = (static_cast<std::int64_t>(dirty_x1_) + 2) * k - 1;
  const std::int64_t sy0 = (static_cast<std::int64_t>(dirty_y0_) - 1) * k, sy1 = (static_cast<std::int64_t>(dirty_y1_) + 2) * k - 1;
  const std::int64_t pages_per_side = static_cast<std::int64_t>(sub_mask_ + 1) >> 6;
  const std::int64_t tx0 = sx0 >> 6, ty0 = sy0 >> 6;  // floor (arithmetic shift, C++20)
  const std::int64_t ntx = std::min((sx1 >> 6) - tx0 + 1, pages_per_side);
  const std::int64_t nty = std::min((sy1 >> 6) - ty0 + 1, pages_per_side);
  const std::int64_t page_mask = pages_per_side - 1;
  for (std::int64_t j = 0; j < nty; ++j) {
    const std::int64_t py = (ty0 + j) & page_mask;
    for (std::int64_t i = 0; i < ntx; ++i) {
      const std::int64_t px = (tx0 + i) & page_mask;
      const std::size_t page = static_cast<std::size_t>((py << (sub_shift_ - 6)) | px);
      std::memset(lookup_ + (page << 12), 0, std::size_t{1} << 12);
    }
  }
}

void EndpointGrid::clear() {
  if (!initialized()) return;
  const std::int64_t w = static_cast<std::int64_t>(dirty_x1_) - dirty_x0_ + 1;
  const std::int64_t h = static_cast<std::int64_t>(dirty_y1_) - dirty_y0_ + 1;
  if (storage_foreign_) {
    // The whole storage, the zero sentinel line included (init()'s state).
    std::memset(occupancy_, 0, static_cast<std::size_t>(side_) * side_);
    std::memset(lookup_, 0, static_cast<std::size_t>(sub_mask_ + 1) * (sub_mask_ + 1) + 64);
    storage_foreign_ = false;
  } else if (w > 0 && h > 0) {
    if (w * h * 2 >= static_cast<std::int64_t>(side_) * side_ || sub_shift_ < 6) {
      std::memset(occupancy_, 0, static_cast<std::size_t>(side_) * side_);
      std::memset(lookup_, 0, static_cast<std::size_t>(sub_mask_ + 1) * (sub_mask_ + 1));
    } else {
      clear_box_rows(w, h);
      clear_box_tiles();
    }
  }
  occupied_count_ = 0;
  dirty_x0_ = dirty_y0_ = 0;
  dirty_x1_ = dirty_y1_ = -1;
  // The window goes back to where init() left it (not centred; the next follow/insert centres it
  // on the robot). Keeping the old window made a run after reset() start in a window shifted by
  // wherever the previous run left it (up to recenter_fraction of the side): other points fell
  // outside it and RBSM's lookup coordinates were relative to another origin, so the same inputs
  // gave a different local map (trial results depended on the trials before them).
  origin_cx_ = origin_cy_ = 0;
  centered_ = false;
  recentring_ = false;
}

void EndpointGrid::center_on(float x, float y) {
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  const std::int32_t half = static_cast<std::int32_t>(side_ / 2);
  if (!centered_) {
    origin_cx_ = gx - half;
    origin_cy_ = gy - half;
    centered_ = true;
    return;
  }
  move_window(gx - half, gy - half);
}

bool EndpointGrid::follow(float x, float y) {
  if (!centered_) {
    center_on(x, y);
    return true;
  }
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  const std::int32_t half = static_cast<std::int32_t>(side_ / 2);
  const std::int32_t limit = static_cast<std::int32_t>(options_.recenter_fraction * static_cast<float>(side_));
  const std::int32_t ox = gx - (origin_cx_ + half), oy = gy - (origin_cy_ + half);
  if (!recentring_ && !(ox > limit || ox < -limit || oy > limit || oy < -limit)) return false;
  const std::int32_t tx = gx - half, ty = gy - half;
  if (options_.recenter_step_cells == 0) {
    move_window(tx, ty);
    return true;
  }
  const std::int32_t m = static_cast<std::int32_t>(options_.recenter_step_cells);
  auto toward = [m](std::int32_t from, std::int32_t to) { return to > from + m ? from + m : to < from - m ? from - m : to; };
  const std::int32_t nx = toward(origin_cx_, tx), ny = toward(origin_cy_, ty);
  move_window(nx, ny);
  recentring_ = nx != tx || ny != ty;
  return true;
}

void EndpointGrid::move_window(std::int32_t nox, std::int32_t noy) {
  const std::int32_t s = static_cast<std::int32_t>(side_);
  const std::int32_t dx = nox - origin_cx_, dy = noy - origin_cy_;
  if (dx == 0 && dy == 0) return;
  if (dx >= s || dx <= -s || dy >= s || dy <= -s) {
    std::memset(occupancy_, 0, static_cast<std::size_t>(side_) * side_);
    std::memset(lookup_, 0, static_cast<std::size_t>(sub_mask_ + 1) * (sub_mask_ + 1));
    occupied_count_ = 0;
    origin_cx_ = nox;
    origin_cy_ = noy;
    return;
  }
  // Global columns of the old window that are not in the new one: clear their storage columns.
  const std::int32_t cx0 = dx > 0 ? origin_cx_ : nox + s, cx1 = dx > 0 ? nox : origin_cx_ + s;  // [cx0, cx1)
  for (std::int32_t gx = cx0; gx < cx1; ++gx) {
    for (std::int32_t gy = origin_cy_; gy < origin_cy_ + s; ++gy) clear_cell(gx, gy);
  }
  const std::int32_t cy0 = dy > 0 ? origin_cy_ : noy + s, cy1 = dy > 0 ? noy : origin_cy_ + s;
  for (std::int32_t gy = cy0; gy < cy1; ++gy) {
    for (std::int32_t gx = origin_cx_; gx < origin_cx_ + s; ++gx) clear_cell(gx, gy);
  }
  origin_cx_ = nox;
  origin_cy_ = noy;
  // Cells on the new border may have been raised by neighbours that just left: recompute them.
  for (std::int32_t i = 0; i < s; ++i) {
    refresh(nox + i, noy);
    refresh(nox + i, noy + s - 1);
    refresh(nox, noy + i);
    refresh(nox + s - 1, noy + i);
  }
}

void EndpointGrid::refresh(std::int32_t gx, std::int32_t gy) {
  bool occ[9];
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) occ[(dy + 1) * 3 + (dx + 1)] = occupied_cell(gx + dx, gy + dy);
  }
  for (std::uint32_t b = 0; b < k_; ++b) {
    const std::uint32_t sy = static_cast<std::uint32_t>(gy) * k_ + b;
    for (std::uint32_t a = 0; a < k_; ++a) {
      std::uint8_t v = 0;
      for (int n = 0; n < 9; ++n) {
        if (occ[n] && table_[n][b * k_ + a] > v) v = table_[n][b * k_ + a];
      }
      lookup_[tiled_index((static_cast<std::uint32_t>(gx) * k_ + a) & sub_mask_, sy & sub_mask_, sub_shift_)] = v;
    }
  }
}

void EndpointGrid::splat(std::int32_t gx, std::int32_t gy) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      // The cell at (gx, gy) − d sees the occupied cell as its neighbour d.
      const std::int32_t cx = gx - dx, cy = gy - dy;
      if (!in_window(cx, cy)) continue;
      const std::uint8_t* t = table_[(dy + 1) * 3 + (dx + 1)];
      for (std::uint32_t b = 0; b < k_; ++b) {
        const std::uint32_t sy = static_cast<std::uint32_t>(cy) * k_ + b;
        for (std::uint32_t a = 0; a < k_; ++a) {
          std::uint8_t& v =
              lookup_[tiled_index((static_cast<std::uint32_t>(cx) * k_ + a) & sub_mask_, sy & sub_mask_, sub_shift_)];
          if (t[b * k_ + a] > v) v = t[b * k_ + a];
        }
      }
    }
  }
}

bool EndpointGrid::insert(float x, float y, float* cx, float* cy) {
  if (!initialized() || !std::isfinite(x) || !std::isfinite(y)) return false;
  if (!centered_) center_on(x, y);
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  if (!in_window(gx, gy)) return false;
  std::uint8_t& c = occupancy_[cell_index(gx, gy)];
  if (c) return false;
  c = 1;
  ++occupied_count_;
  if (dirty_x1_ < dirty_x0_) {
    dirty_x0_ = dirty_x1_ = gx;
    dirty_y0_ = dirty_y1_ = gy;
  } else {
    if (gx < dirty_x0_) dirty_x0_ = gx;
    if (gx > dirty_x1_) dirty_x1_ = gx;
    if (gy < dirty_y0_) dirty_y0_ = gy;
    if (gy > dirty_y1_) dirty_y1_ = gy;
  }
  splat(gx, gy);
  if (cx) *cx = (static_cast<float>(gx) + 0.5f) * options_.resolution;
  if (cy) *cy = (static_cast<float>(gy) + 0.5f) * options_.resolution;
  return true;
}

bool EndpointGrid::occupied(float x, float y) const {
  if (!initialized() || !std::isfinite(x) || !std::isfinite(y)) return false;
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  return occupied_cell(gx, gy);
}

std::uint8_t EndpointGrid::likelihood(float x, float y) const {
  if (!initialized() || !std::isfinite(x) || !std::isfinite(y)) return 0;
  const LookupView v = lookup_view();
  const float fx = (x - v.origin_x) * v.inv_subcell, fy = (y - v.origin_y) * v.inv_subcell;
  if (!(fx >= 0.0f && fx < v.extent && fy >= 0.0f && fy < v.extent)) return 0;
  const std::uint32_t sx = static_cast<std::uint32_t>(static_cast<std::int32_t>(fx) + v.origin_sx) & v.mask;
  const std::uint32_t sy = static_cast<std::uint32_t>(static_cast<std::int32_t>(fy) + v.origin_sy) & v.mask;
  return v.values[tiled_index(sx, sy, v.shift)];
}

EndpointGrid::LookupView EndpointGrid::lookup_view() const {
  LookupView v;
  v.values = lookup_;
  v.origin_x = static_cast<float>(origin_cx_) * options_.resolution;
  v.origin_y = static_cast<float>(origin_cy_) * options_.resolution;
  v.inv_subcell = static_cast<float>(k_) / options_.resolution;
  v.extent = static_cast<float>(side_ * k_);
  v.origin_sx = origin_cx_ * static_cast<std::int32_t>(k_);
  v.origin_sy = origin_cy_ * static_cast<std::int32_t>(k_);
  v.mask = sub_mask_;
  v.shift = sub_shift_;
  v.zero_index = static_cast<std::uint32_t>(static_cast<std::size_t>(sub_mask_ + 1) * (sub_mask_ + 1));
  return v;
}

bool EndpointGrid::nearest_occupied(float x, float y, float max_dist_m, float* nx, float* ny, float* dist2_m) const {
  if (!initialized() || !std::isfinite(x) || !std::isfinite(y)) return false;
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  const float res = options_.resolution;
  const std::int32_t rmax = static_cast<std::int32_t>(std::ceil(max_dist_m / res)) + 1;
  float best = max_dist_m * max_dist_m;
  bool found = false;
  for (std::int32_t r = 0; r <= rmax; ++r) {
    // Every cell of ring r is at least (r − 1) cells from the query point.
    const float ring_min = static_cast<float>(r > 0 ? r - 1 : 0) * res;
    if (ring_min * ring_min > best) break;
    for (std::int32_t j = -r; j <= r; ++j) {
      const std::int32_t step = (j == -r || j == r || r == 0) ? 1 : 2 * r;  // ring cells only
      for (std::int32_t i = -r; i <= r; i += step) {
        const std::int32_t cx = gx + i, cy = gy + j;
        if (!occupied_cell(cx, cy)) continue;
        const float mx = (static_cast<float>(cx) + 0.5f) * res, my = (static_cast<float>(cy) + 0.5f) * res;
        const float d2 = (mx - x) * (mx - x) + (my - y) * (my - y);
        if (d2 <= best) {
          if (!found || d2 < best) {
            best = d2;
            *nx = mx;
            *ny = my;
          }
          found = true;
        }
      }
    }
  }
  if (found && dist2_m) *dist2_m = best;
  return found;
}

void EndpointGrid::local_scatter(float x, float y, std::int32_t radius, LocalScatter* out) const {
  *out = LocalScatter{};
  if (!initialized() || !centered_ || !std::isfinite(x) || !std::isfinite(y)) return;
  if (radius < 0) radius = 0;
  if (radius > 4) radius = 4;
  std::int32_t gx, gy;
  world_to_cell(x, y, &gx, &gy);
  // Integer offsets (cells) from the query cell: exact sums, no cancellation.
  std::int32_t n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  const std::int32_t r2 = radius * radius + radius;  // a disc including the 4-neighbours of its rim
  for (std::int32_t dy = -radius; dy <= radius; ++dy) {
    for (std::int32_t dx = -radius; dx <= radius; ++dx) {
      if (dx * dx + dy * dy > r2 || !occupied_cell(gx + dx, gy + dy)) continue;
      ++n;
      sx += dx;
      sy += dy;
      sxx += dx * dx;
      sxy += dx * dy;
      syy += dy * dy;
    }
  }
  if (n == 0) return;
  const float res = options_.resolution, inv = 1.0f / static_cast<float>(n);
  const float mx = static_cast<float>(sx) * inv, my = static_cast<float>(sy) * inv;
  out->count = static_cast<std::uint32_t>(n);
  out->cx = (static_cast<float>(gx) + 0.5f + mx) * res;
  out->cy = (static_cast<float>(gy) + 0.5f + my) * res;
  out->sxx = (static_cast<float>(sxx) * inv - mx * mx) * res * res;
  out->sxy = (static_cast<float>(sxy) * inv - mx * my) * res * res;
  out->syy = (static_cast<float>(syy) * inv - my * my) * res * res;
}

std::size_t EndpointGrid::insert_scan(const Point2f* points, std::size_t count, float pose_x, float pose_y,
                                      float pose_theta, float max_range, Point2f* new_cells, std::size_t capacity) {
  follow(pose_x, pose_y);
  const float c = std::cos(pose_theta), s = std::sin(pose_theta);
  const float max_r2 = max_range > 0.0f ? max_range * max_range : 0.0f;
  std::size_t n = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const float px = points[i](0), py = points[i](1);
    if (!std::isfinite(px) || !std::isfinite(py)) continue;
    if (max_r2 > 0.0f && px * px + py * py > max_r2) continue;
    float cx, cy;
    if (insert(pose_x + c * px - s * py, pose_y + s * px + c * py, &cx, &cy)) {
      if (new_cells != nullptr && n < capacity) new_cells[n++] = Point2f(cx, cy);
    }
  }
  return n;
}

}  // namespace fw
