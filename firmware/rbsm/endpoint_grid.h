// EndpointGrid: the binary end-point map M_t of RBSM (Sec. 2.3: every accepted scan point sets its
// grid cell) in a bounded, scrolling window, plus the precomputed bounded nearest-neighbour
// likelihood that RBSM's weights need (Eq. 2.9–2.10).
//
// Window: 2^size_log2 cells per side around the robot, stored toroidally (storage index = global
// cell index mod side), so following the robot only clears the strips that leave the window —
// logs are hundreds of metres long, memory is fixed at init.
//
// Likelihood lookup: for every sub-cell (side = resolution / 2^subcell_log2) the value
// 255·exp(−d²) with d the distance (in cells) from the sub-cell centre to the nearest occupied
// cell centre, or 0 if d > ξ (Eq. 2.9). With ξ ≤ 1.5 cells the nearest occupied centre within ξ
// always lies in the 3×3 cells around the query's cell ("searched only in neighbouring cells"),
// so the lookup is maintained incrementally: setting a cell raises the values of its 3×3
// neighbourhood. Scan points are quantised to the sub-cell grid (default 1/4 cell), which is the
// only approximation versus evaluating Eq. 2.9 at the exact point.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/scan/scan_points.h"

namespace fw {

struct EndpointGridOptions {
  float resolution = 0.05f;        // m per cell (thesis: 1–5 cm)
  std::uint32_t size_log2 = 10;    // window side = 2^size_log2 cells (1024 × 5 cm = 51.2 m)
  std::uint32_t subcell_log2 = 2;  // lookup sub-cells per cell side = 2^subcell_log2
  float xi_cells = 1.41421356f;    // ξ: bound of the nearest-neighbour distance (Eq. 2.9), ≤ 1.5
  float recenter_fraction = 0.25f; // re-centre when the robot is this fraction of the side off-centre
  // Anytime re-centre (issue 14): 0 = the whole shift at once (a 256-cell shift of the 1024-cell
  // window clears 2 × 256k cells: 11–22 ms in one step); n > 0 = at most n cells per axis per
  // follow() until the window is centred again, so the cost is spread over the following steps
  // (a robot moves < 1 cell per scan at 75 Hz, so the window catches up).
  std::uint32_t recenter_step_cells = 0;

  Status validate() const;
};

class EndpointGrid {
 public:
  static constexpr std::uint8_t kLikelihoodMax = 255;

  // Bytes the arena must provide for these options (occupancy + lookup).
  static std::size_t required_bytes(const EndpointGridOptions& options);

  Status init(const EndpointGridOptions& options, StartupArena& arena);
  bool initialized() const { return occupancy_ != nullptr; }
  const EndpointGridOptions& options() const { return options_; }

  // Removes every point (only the region ever written is cleared) and returns the window to its
  // state after init(): not centred, so the next follow()/insert() centres it afresh.
  void clear();
  // The grid's storage was written by another grid since this one last cleared it (several maps
  // share RBSM's working memory: firmware/app/map_set.h): the next clear() wipes all of it, since
  // the dirty box only knows what this grid wrote.
  void mark_storage_foreign() { storage_foreign_ = true; }
  // Centres the window on (x, y) (world, m); call once before the first insert.
  void center_on(float x, float y);
  // Re-centres when (x, y) is more than recenter_fraction of the side away from the centre;
  // cells leaving the window are dropped. Returns true if the window moved.
  bool follow(float x, float y);

  // Sets the cell containing world point (x, y). Returns true if the cell was newly occupied
  // (then *cx, *cy receive its centre); false if already occupied or outside the window.
  bool insert(float x, float y, float* cx = nullptr, float* cy = nullptr);
  // A scan's end-points (robot frame) placed at `pose` (world): follow(pose), then insert every finite
  // point within max_range (0 = all); the newly occupied cell centres go to new_cells (up to
  // capacity), their count to *num_new. The map update of every ScanMatcher built on this grid.
  std::size_t insert_scan(const Point2f* points, std::size_t count, float pose_x, float pose_y, float pose_theta,
                          float max_range, Point2f* new_cells, std::size_t capacity);
  bool occupied(float x, float y) const;
  std::size_t occupied_count() const { return occupied_count_; }

  // 255·exp(−d²) at the sub-cell of (x, y), 0 when d > ξ or outside the window.
  std::uint8_t likelihood(float x, float y) const;
  // Nearest occupied cell centre within max_dist_m of (x, y) (exact search over rings of cells).
  bool nearest_occupied(float x, float y, float max_dist_m, float* nx, float* ny, float* dist2_m) const;

  // The occupied cell centres within radius_cells (a disc, ≤ 4 cells) of the cell of (x, y): their
  // count, centroid (world, m) and second moments about the centroid (m²). The local surface the
  // accepted end-points were drawn from, for RBSM's point-to-line refinement (issue 15).
  struct LocalScatter {
    std::uint32_t count = 0;
    float cx = 0, cy = 0, sxx = 0, sxy = 0, syy = 0;
  };
  void local_scatter(float x, float y, std::int32_t radius_cells, LocalScatter* out) const;

  // Storage index of sub-cell (sx, sy) (already masked to the window) in the tiled lookup: 8×8
  // sub-cells per 64-byte line, 8×8 lines per 4 KiB page, pages row-major. A particle cloud's
  // points for one beam then touch a few lines on one or two pages instead of one page per row
  // (row-major storage thrashed the TLB: ~20 ms per match instead of ~2 ms).
  static std::uint32_t tiled_index(std::uint32_t sx, std::uint32_t sy, std::uint32_t shift) {
    const std::uint32_t page = ((sy >> 6) << (shift - 6)) | (sx >> 6);
    return (page << 12) | (((sy >> 3) & 7u) << 9) | (((sx >> 3) & 7u) << 6) | ((sy & 7u) << 3) | (sx & 7u);
  }

  // Raw view for the vectorisable inner loop of RBSM's weighting (see rbsm.cpp).
  struct LookupView {
    const std::uint8_t* values;
    float origin_x, origin_y;   // world position of the window's lower-left corner (m)
    float inv_subcell;          // sub-cells per metre
    float extent;               // window side in sub-cells (as float, for the bounds test)
    std::int32_t origin_sx, origin_sy;  // global sub-cell index of the lower-left corner
    std::uint32_t mask;         // side in sub-cells − 1
    std::uint32_t shift;        // log2(side in sub-cells); index with tiled_index()
    std::uint32_t zero_index;   // values[zero_index] is always 0 (outside-the-window sentinel)
  };
  LookupView lookup_view() const;

  // Window geometry in global cell indices (lower-left corner) and the side length.
  std::int32_t origin_cx() const { return origin_cx_; }
  std::int32_t origin_cy() const { return origin_cy_; }
  std::uint32_t side() const { return side_; }
  float resolution() const { return options_.resolution; }

 private:
  void clear_box_rows(std::int64_t w, std::int64_t h);
  void clear_box_tiles();
  std::size_t cell_index(std::int32_t gx, std::int32_t gy) const {
    return (static_cast<std::size_t>(static_cast<std::uint32_t>(gy) & cell_mask_) << options_.size_log2) |
           (static_cast<std::uint32_t>(gx) & cell_mask_);
  }
  bool in_window(std::int32_t gx, std::int32_t gy) const {
    return static_cast<std::uint32_t>(gx - origin_cx_) < side_ && static_cast<std::uint32_t>(gy - origin_cy_) < side_;
  }
  bool occupied_cell(std::int32_t gx, std::int32_t gy) const {
    return in_window(gx, gy) && occupancy_[cell_index(gx, gy)] != 0;
  }
  void world_to_cell(float x, float y, std::int32_t* gx, std::int32_t* gy) const;
  // Raises the lookup of the 3×3 neighbourhood of newly occupied cell (gx, gy).
  void splat(std::int32_t gx, std::int32_t gy);
  // Recomputes the lookup of cell (gx, gy) from the occupancy of its 3×3 neighbourhood.
  void refresh(std::int32_t gx, std::int32_t gy);
  void clear_cell(std::int32_t gx, std::int32_t gy);
  void move_window(std::int32_t new_ox, std::int32_t new_oy);

  EndpointGridOptions options_;
  std::uint8_t* occupancy_ = nullptr;  // side² cells
  std::uint8_t* lookup_ = nullptr;     // (side·k)² sub-cells
  std::uint32_t side_ = 0, cell_mask_ = 0, k_ = 1, sub_mask_ = 0, sub_shift_ = 0;
  std::int32_t origin_cx_ = 0, origin_cy_ = 0;
  bool centered_ = false;
  bool recentring_ = false;  // an incremental re-centre is under way
  bool storage_foreign_ = false;
  std::size_t occupied_count_ = 0;
  // Bounding box (global cells) of everything written since the last clear().
  std::int32_t dirty_x0_ = 0, dirty_y0_ = 0, dirty_x1_ = -1, dirty_y1_ = -1;
  // table_[n][s]: likelihood contribution of neighbour n (3×3, row-major, dy outer) to sub-cell s.
  static constexpr std::uint32_t kMaxSub = 8;
  std::uint8_t table_[9][kMaxSub * kMaxSub] = {};
};

}  // namespace fw
