// Scan-to-map residuals of the grounding measurement (issue 55, item 6): the distance of every beam
// end-point, placed at the scan's reference (or true) laser pose, to the nearest occupied cell of the
// global map — the exact Euclidean distance transform of the map's occupied cells (fw::squared_edt,
// firmware/map/edt.h, the one the map compiler uses), interpolated bilinearly between the cell
// centres around the end-point (so a point on a wall cell reads 0 to half a cell, not exactly 0). The same
// function is applied to the real logs on their global maps and to simulated scans on a rasterized
// built-in world. Beams that are "no return" (≥ the scan's maximum range), below its minimum range or
// beyond max_range_m (the tracker's 30 m, as sim/eval/mml_eval/unmapped_scan.h) are not end-points.
// An end-point off the grid gets the distance to the grid's border plus the border cell's distance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "firmware/base/se2.h"
#include "sim/io/ros_map.h"

namespace sim::ground {

class MapDistance {
 public:
  // Occupied: cell value ≥ occupied_at (100 = occupied in the firmware convention).
  explicit MapDistance(const OccupancyGrid& grid, std::uint8_t occupied_at = 100);
  // Metres from (x, y) (world) to the nearest occupied cell centre; +inf on a map without any.
  double at(double x, double y) const;
  std::size_t occupied_cells() const { return occupied_; }

 private:
  fw::GridGeometry geo_;
  std::vector<float> dist_m_;
  std::size_t occupied_ = 0;
};

struct ResidualOptions {
  double max_range_m = 30.0;
  double unexplained_m = 0.3;  // beyond: people, clutter, glass, map errors
};

// Bin edges of the histogram (m): [0, 0.05), [0.05, 0.1), … [0.3, 0.5), [0.5, 1), [1, ∞).
const std::vector<double>& residual_bin_edges();

struct ResidualSample {
  std::vector<float> d;  // every end-point's distance
  std::size_t scans = 0;
  void add_scan(const MapDistance& map, const fw::Se2d& laser_pose, float angle_min, float angle_increment,
                float range_min, float range_max, const float* ranges, std::size_t count, const ResidualOptions& opt);
};

struct ResidualSummary {
  std::size_t scans = 0, points = 0;
  double p50 = 0, p90 = 0, p99 = 0;
  double beyond = 0;           // fraction of end-points beyond unexplained_m
  std::vector<double> histogram;  // fractions per bin of residual_bin_edges()
};

ResidualSummary summarize(const ResidualSample& s, const ResidualOptions& opt);

}  // namespace sim::ground
