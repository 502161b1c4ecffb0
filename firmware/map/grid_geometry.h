// GridGeometry: where a 2D grid sits in the world. Cell (0,0) is the LOWEST-y row (unlike a PGM,
// whose first row is the top of the image); origin is the world position of that cell's outer
// corner, as the ROS map_server `origin` (yaw 0) is the lower-left pixel's corner.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace fw {

// Same alias as firmware/scan/scan_points.h (a redeclaration to the same type is legal C++).
using Point2f = Eigen::Matrix<float, 2, 1>;

struct GridGeometry {
  float resolution = 0.0f;  // metres per cell (> 0)
  float origin_x = 0.0f;    // world x of the corner of cell (0,0)
  float origin_y = 0.0f;    // world y of the corner of cell (0,0)
  std::uint32_t width = 0;   // cells along x
  std::uint32_t height = 0;  // cells along y (rows)

  std::size_t cell_count() const { return static_cast<std::size_t>(width) * height; }
  bool contains(std::int32_t cx, std::int32_t cy) const {
    return cx >= 0 && cy >= 0 && static_cast<std::uint32_t>(cx) < width && static_cast<std::uint32_t>(cy) < height;
  }
  // Row-major index, row = cy (lowest y first).
  std::size_t index(std::int32_t cx, std::int32_t cy) const {
    return static_cast<std::size_t>(cy) * width + static_cast<std::size_t>(cx);
  }
  // Cell containing world point (x, y) (floor); true when it lies inside the grid. NaN => false.
  bool world_to_cell(float x, float y, std::int32_t* cx, std::int32_t* cy) const {
    const float fx = std::floor((x - origin_x) / resolution);
    const float fy = std::floor((y - origin_y) / resolution);
    // Compare in float first: casting a NaN/huge float to int is undefined.
    if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(width) && fy < static_cast<float>(height))) {
      return false;
    }
    *cx = static_cast<std::int32_t>(fx);
    *cy = static_cast<std::int32_t>(fy);
    return contains(*cx, *cy);
  }
  // Continuous cell coordinates (cell (i,j) spans [i, i+1) × [j, j+1)); for interpolation.
  void world_to_grid(float x, float y, float* gx, float* gy) const {
    *gx = (x - origin_x) / resolution;
    *gy = (y - origin_y) / resolution;
  }
  Point2f cell_center(std::int32_t cx, std::int32_t cy) const {
    return Point2f(origin_x + (static_cast<float>(cx) + 0.5f) * resolution,
                   origin_y + (static_cast<float>(cy) + 0.5f) * resolution);
  }
  float size_x() const { return static_cast<float>(width) * resolution; }
  float size_y() const { return static_cast<float>(height) * resolution; }
};

// What float world coordinates can represent. A float has 24 significant bits, so its spacing at |x|
// is at most |x|·2^-23; a grid reaching 2^19 cells from the world origin still resolves 1/16 of a cell
// there (a 0.05 m map: ±26 km). Beyond that cell centres and scan end-points collapse onto each other
// (an origin of -1e38 puts every cell on the same float) — such a map is refused, not compiled or
// loaded. The resolution bounds only exclude nonsense (0.1 mm .. 1 km cells).
constexpr double kMinGridResolutionM = 1e-4;
constexpr double kMaxGridResolutionM = 1e3;
constexpr double kMaxGridReachCells = 524288.0;  // 2^19

enum class GridExtentProblem { kNone, kResolution, kOrigin, kReach };

// Largest |world coordinate| of the grid's corners (metres); inf/NaN when not finite.
inline double grid_reach_m(double resolution, double origin_x, double origin_y, double width, double height) {
  const double x1 = origin_x + width * resolution, y1 = origin_y + height * resolution;
  return std::fmax(std::fmax(std::fabs(origin_x), std::fabs(x1)), std::fmax(std::fabs(origin_y), std::fabs(y1)));
}

// Checked in double, before any conversion to float (origin 1e39 is finite as a double, inf as a float).
inline GridExtentProblem check_grid_extent(double resolution, double origin_x, double origin_y, double width,
                                           double height) {
  if (!(resolution >= kMinGridResolutionM && resolution <= kMaxGridResolutionM)) return GridExtentProblem::kResolution;
  if (!std::isfinite(origin_x) || !std::isfinite(origin_y)) return GridExtentProblem::kOrigin;
  const double reach = grid_reach_m(resolution, origin_x, origin_y, width, height);
  if (!(reach <= kMaxGridReachCells * resolution)) return GridExtentProblem::kReach;
  return GridExtentProblem::kNone;
}
inline GridExtentProblem check_grid_extent(const GridGeometry& g) {
  return check_grid_extent(g.resolution, g.origin_x, g.origin_y, g.width, g.height);
}

}  // namespace fw
