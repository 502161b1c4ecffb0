// Small synthetic grid worlds with a distance image, shared by the MCL and MML tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "firmware/map/distance_field.h"
#include "firmware/map/edt.h"
#include "firmware/baselines/mcl/map_view.h"
#include "hal/msg/laser_scan.h"

namespace fw {
namespace mcl {
namespace testing {

struct GridWorld {
  float res = 0.05f;
  std::uint32_t w = 0, h = 0;
  std::vector<std::uint8_t> occ;
  std::vector<float> dist;  // exact metres (finish())
  // The truncated, tiled field the localizers read (finish(); distance_field.h).
  DistanceFieldLayout dist_layout;
  std::vector<std::uint32_t> dist_slots;
  std::vector<std::uint16_t> dist_cells;
  std::vector<float> dist_table;
  OccupancyTilesLayout occ_layout;
  std::vector<std::uint32_t> occ_slots;
  std::vector<std::uint8_t> occ_cells;
  OccupancyTiles occupancy_tiles() const {
    return occupancy_tiles_view(occ_layout, occ_slots.data(), occ_cells.data());
  }
  DistanceField distance_field() const {
    return distance_field_view(dist_layout, dist_slots.data(), dist_cells.data(), dist_table.data());
  }
  MapView view() const {
    MapView v;
    v.resolution = res;
    v.width = w;
    v.height = h;
    v.occupancy = occupancy_tiles();
    v.distance = distance_field();
    return v;
  }
  void wall(float x0, float y0, float x1, float y1) {
    const int n = static_cast<int>(std::hypot(x1 - x0, y1 - y0) / (0.5f * res)) + 1;
    for (int i = 0; i <= n; ++i) {
      const float t = static_cast<float>(i) / n;
      const int cx = static_cast<int>((x0 + t * (x1 - x0)) / res), cy = static_cast<int>((y0 + t * (y1 - y0)) / res);
      if (cx >= 0 && cy >= 0 && cx < static_cast<int>(w) && cy < static_cast<int>(h)) occ[cy * w + cx] = 100;
    }
  }
  void box(float x0, float y0, float x1, float y1) {
    wall(x0, y0, x1, y0); wall(x1, y0, x1, y1); wall(x1, y1, x0, y1); wall(x0, y1, x0, y0);
  }
  void finish() {
    std::vector<float> f(w * h);
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = occ[i] == 100 ? 0.0f : kEdtInf;
    const std::size_t n = w > h ? w : h;
    std::vector<int> v(n);
    std::vector<float> z(n + 1), ff(n), d(n);
    EdtScratch s{v.data(), z.data(), ff.data(), d.data(), n};
    const std::size_t dims[2] = {h, w};
    squared_edt<2>(f.data(), dims, s);
    dist.resize(w * h);
    for (std::size_t i = 0; i < f.size(); ++i) dist[i] = std::sqrt(f[i]) * res;
    (void)plan_distance_field(dist.data(), w, h, res, kDefaultDistanceTruncationM, &dist_layout);
    dist_slots.assign(dist_layout.slot_count(), 0);
    dist_cells.assign(dist_layout.cell_count(), 0);
    dist_table.assign(dist_layout.table_count(), 0.0f);
    fill_distance_field(dist_layout, dist.data(), dist_slots.data(), dist_cells.data(), dist_table.data());
    (void)plan_occupancy_tiles(occ.data(), w, h, &occ_layout);
    occ_slots.assign(occ_layout.slot_count(), 0);
    occ_cells.assign(occ_layout.cell_count(), 0);
    fill_occupancy_tiles(occ_layout, occ.data(), occ_slots.data(), occ_cells.data());
  }
};

// A 12 × 8 m room with an asymmetric set of inner walls (a unique layout).
inline GridWorld unique_room() {
  GridWorld g;
  g.w = 240; g.h = 160;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.2f, 0.2f, 11.8f, 7.8f);
  g.wall(3.0f, 0.2f, 3.0f, 3.0f);
  g.wall(7.0f, 7.8f, 7.0f, 5.0f);
  g.box(8.5f, 1.5f, 9.5f, 2.2f);
  g.wall(5.0f, 4.0f, 6.5f, 4.0f);
  g.finish();
  return g;
}

// Simulated scan: exact sphere tracing on the same grid, 181 beams over 180°.
inline void simulate_scan(const MapView& map, float x, float y, float th, hal::LaserScan* s, float maxr = 8.0f) {
  s->beam_count = 181;
  s->angle_min = -1.5707963f;
  s->angle_increment = 3.14159265f / 180.0f;
  s->range_min = 0.05f;
  s->range_max = maxr;
  for (std::uint32_t i = 0; i < s->beam_count; ++i) {
    s->ranges[i] = map.raycast(x, y, th + s->angle_min + s->angle_increment * i, maxr);
  }
}

}  // namespace testing
}  // namespace mcl
}  // namespace fw
