// Host writer of the compiled map image (format: firmware/map/map_image.h). Builds the four map
// sections from a ROS map / occupancy grid (distance field by the firmware's own exact EDT,
// fw::squared_edt<2>), lets other modules append sections, and writes the blob with CRC-32s
// computed by zlib (the firmware recomputes them with its own table-driven CRC).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/map/map_image.h"
#include "sim/io/ros_map.h"

namespace sim {

class MapImageWriter {
 public:
  // Replaces the map sections (geometry, occupancy, distance field, occupied points).
  bool set_map(const RosMap& map, std::string* error);
  bool set_grid(const OccupancyGrid& grid, std::string* error);
  // Appends a section (e.g. pRANSAM's kRelationTable2D). Map section types are refused (use set_*).
  bool add_section(fw::MapSectionType type, std::vector<std::uint8_t> bytes, std::uint32_t version, std::string* error);
  // The whole image; empty if no map was set.
  std::vector<std::uint8_t> bytes() const;
  bool write(const std::string& path, std::string* error) const;

 private:
  struct Section {
    fw::MapSectionType type;
    std::uint32_t version;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Section> map_sections_;
  std::vector<Section> extra_sections_;
};

// Distance field in metres (exact EDT of the occupied cells, 0 on them), row 0 = lowest y.
// Cells are "occupied" when == 100. A grid without occupied cells yields an error.
bool distance_field_m(const OccupancyGrid& grid, std::vector<float>* out, std::string* error);

// One-call helpers.
bool compile_map_image(const RosMap& map, std::vector<std::uint8_t>* out, std::string* error);
// Regular files only, at most kMaxMapFileBytes (sim/io/file_io.h); writes go to a temporary file
// renamed over `path` when complete (a failure leaves `path` as it was).
bool read_file_bytes(const std::string& path, std::vector<std::uint8_t>* out, std::string* error);
bool write_file_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes, std::string* error);

}  // namespace sim
