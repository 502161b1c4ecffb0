// Occupancy-grid mapping with known poses: every beam is ray-cast with Bresenham's line algorithm
// through a log-odds grid (Thrun, Burgard & Fox, Probabilistic Robotics, ch. 9): cells the beam
// crosses get l_free, the end cell l_occ. With l_occ = 0.9 and l_free = -0.3 a cell ends up
// occupied when more than a quarter of the beams that reached it ended there (the GMapping
// occupancy threshold 0.25), which keeps thin walls hit at grazing angles while erasing people
// who walked through. Cells no beam reached stay unknown.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "sim/io/ros_map.h"

namespace sim {

struct PosedScan {
  fw::Se2d pose;  // laser pose in the map frame
  float angle_min = 0, angle_increment = 0;
  float max_range = 0;  // readings ≥ max_range - 1 cm are "no return"
  const float* ranges = nullptr;
  std::size_t count = 0;
};

struct OccupancyBuildOptions {
  double resolution = 0.05;        // m per cell
  double max_usable_range = 30.0;  // longer readings: free up to here, no end point (GMapping maxUrange)
  bool free_on_no_return = false;  // "no return" beams clear free space up to max_usable_range (off:
                                   // they pass through windows and would free the outdoors)
  double margin = 1.0;             // m of unknown border around everything observed
  float l_occ = 0.9f, l_free = -0.3f;
  float occupied_logodds = 0.0f;   // L > this → occupied; visited cells otherwise free
  std::size_t beam_stride = 1;
  std::size_t max_cells = 100u * 1000u * 1000u;  // refuse absurd grids (bad poses) with an error
};

struct OccupancyBuildStats {
  std::size_t scans = 0, beams = 0, hits = 0, no_return = 0, truncated = 0, invalid = 0;
  std::size_t occupied = 0, free = 0, unknown = 0;
};

bool build_occupancy_grid(const std::vector<PosedScan>& scans, const OccupancyBuildOptions& options,
                          OccupancyGrid* out, OccupancyBuildStats* stats, std::string* error);

}  // namespace sim
