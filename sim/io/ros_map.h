// ROS map_server maps: a PGM image (P2 ASCII or P5 binary, 8-bit, any maxval 1..255) plus its YAML
// description (image, resolution, origin, negate, occupied_thresh, free_thresh, mode). Read, write
// (bit-exact round trip of what we write), validate with errors naming file and field, and convert
// to an occupancy grid / occupied-cell point cloud with the map_server semantics. The YAML is read
// with yaml-cpp (issue 60): every valid map_server file loads; a syntax error names the library's
// line and column.
// (Owner: maps; compiled into library sim_map.)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/map/grid_geometry.h"

namespace sim {

struct RosMap {
  std::string yaml_path;             // set by read_ros_map (informational)
  std::string image;                 // as written in the YAML (relative paths are relative to the YAML's folder)
  double resolution = 0.05;          // metres per pixel
  double origin[3] = {0.0, 0.0, 0.0};  // x, y, yaw of the lower-left pixel's corner (yaw must be 0 for grids)
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  std::string mode = "trinary";      // trinary | scale | raw
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // row-major, first row = top of the image as in PGM
  // Additions to the interface (for bit-exact round trips): PGM maxval and encoding.
  int maxval = 255;
  bool pgm_ascii = false;            // true: P2, false: P5
};

bool read_ros_map(const std::string& yaml_path, RosMap* out, std::string* error);
// Writes the YAML and the PGM (named by map.image, or <yaml stem>.pgm when empty).
bool write_ros_map(const std::string& yaml_path, const RosMap& map, std::string* error);

// PGM alone (used by the above and the tests).
bool read_pgm(const std::string& path, RosMap* out, std::string* error);  // fills width/height/pixels/maxval/pgm_ascii
bool write_pgm(const std::string& path, const RosMap& map, std::string* error);

// Checks the YAML-level fields and pixel buffer (size, values ≤ maxval); message names the field.
bool validate_ros_map(const RosMap& map, const std::string& name, std::string* error);

// Occupancy grid in the firmware convention: row 0 = lowest y; 0 free, 1..99 scaled, 100 occupied,
// 255 unknown (map_server: p = (maxval - v)/maxval, or v/maxval with negate; p > occupied_thresh →
// occupied, p < free_thresh → free, else unknown (trinary) or scaled (scale); raw: v itself).
struct OccupancyGrid {
  fw::GridGeometry geometry;
  std::vector<std::uint8_t> cells;
};
bool ros_map_to_grid(const RosMap& map, OccupancyGrid* out, std::string* error);
// Inverse for writing built maps: trinary image (0 occupied, 254 free, 205 unknown), like map_saver.
RosMap grid_to_ros_map(const OccupancyGrid& grid, const std::string& image_name);

// Centres of the occupied cells (world metres), row-major from the lowest row.
std::vector<fw::Point2f> occupied_points(const OccupancyGrid& grid);
bool ros_map_occupied_points(const RosMap& map, std::vector<fw::Point2f>* out, std::string* error);

}  // namespace sim
