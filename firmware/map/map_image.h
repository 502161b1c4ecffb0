// Compiled map image: one versioned binary blob that the host tool `mml-mapc` (sim/map) builds from
// a ROS map (PGM+YAML) and the firmware validates and loads ONCE at start-up into its StartupArena.
// Other modules append their own sections (pRANSAM's precomputed relation table, …) and read them
// back with find_section() after load_map_image() has verified the whole image.
//
// Layout (all integers/floats little-endian, IEEE-754 float32):
//   header, 32 bytes:
//     0  char[8] magic "MMLFWMAP"
//     8  u32 version            (kMapImageVersion; any other value is rejected)
//    12  u32 section_count      (≤ kMaxMapSections)
//    16  u64 total_size         (must equal the number of bytes given)
//    24  u32 flags              (0)
//    28  u32 image_crc          (CRC-32 of the whole image with these 4 bytes read as zero)
//   section table, section_count × 32 bytes at offset 32:
//     0  u32 type (MapSectionType)   4 u32 section version
//     8  u64 offset (from image start, 16-byte aligned, after the table)
//    16  u64 size (payload bytes)    24 u32 payload CRC-32   28 u32 reserved (0)
//   payloads, 16-byte aligned, zero padding between, non-overlapping.
//
// Required sections (version 1):
//   kGeometry       32 bytes: f32 resolution, f32 origin_x, f32 origin_y, u32 width, u32 height,
//                   u32 num_points, f32 max_distance_m, u32 reserved(0)
//   kOccupancy      width*height u8, row 0 = lowest y (0 free, 1..99 scaled, 100 occupied, 255 unknown)
//   kDistanceField  width*height f32 metres to the nearest occupied cell (exact EDT, 0 on occupied)
//   kOccupiedPoints num_points × (f32 x, f32 y): centres of the occupied cells, row-major order
// Reserved fields and the padding between sections are zero; the grid must satisfy
// check_grid_extent() (grid_geometry.h: float coordinates resolve its cells).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/map/global_map.h"

namespace fw {

constexpr char kMapImageMagic[8] = {'M', 'M', 'L', 'F', 'W', 'M', 'A', 'P'};
constexpr std::uint32_t kMapImageVersion = 1;
constexpr std::size_t kMapImageHeaderBytes = 32;
constexpr std::size_t kMapSectionEntryBytes = 32;
constexpr std::size_t kMaxMapSections = 64;
constexpr std::size_t kMapSectionAlignment = 16;
constexpr std::size_t kMapGeometryBytes = 32;

// Section types. Values are part of the file format: never renumber, only append.
enum class MapSectionType : std::uint32_t {
  kGeometry = 1,
  kOccupancy = 2,
  kDistanceField = 3,
  kOccupiedPoints = 4,
  kRelationTable2D = 16,  // pRANSAM precomputed relation table (owner: pransam)
  kRelationTable3D = 17,
  kUser = 0x1000,         // first value free for experiments
};
// Name agreed in the interface document (§2).
using SectionType = MapSectionType;

const char* map_section_name(MapSectionType type);

struct MapLoadOptions {
  // The distance field is kept as min(d, truncation) in tiles (distance_field.h): memory grows with
  // the area within the truncation of a wall, not with the bounding box.
  float distance_truncation_m = kDefaultDistanceTruncationM;
};

struct MapSectionInfo {
  MapSectionType type = MapSectionType::kGeometry;
  std::uint32_t version = 0;
  std::uint64_t offset = 0;
  std::uint64_t size = 0;
  std::uint32_t crc = 0;
};

// Structure + CRC check of any image (header, table bounds/overlaps, every section CRC, whole-image
// CRC); does not interpret the sections. `name` (e.g. the file path) prefixes every message.
Status verify_map_image(const std::uint8_t* bytes, std::size_t size, const char* name = "map image");

// Full validation (verify_map_image + the four map sections: sizes consistent with the geometry, a
// representable grid extent, finite floats, occupancy codes, at least one occupied cell, exactly one
// point at the centre of each occupied cell in row-major order, reserved fields zero, and the distance
// field equal to the exact EDT of the occupied cells, recomputed here), then copies the arrays into
// `arena` and fills `out` (the distance field truncated at options.distance_truncation_m and tiled:
// distance_field.h). Nothing stays allocated unless the whole image is valid. The recomputation
// needs map_image_arena_bytes() of arena at its peak (a dense float field of scratch, released before
// returning: load the map before the other modules allocate, so the peak is not added to theirs) and costs
// about as much as the writer's EDT (see sim/map/README.md for figures). Registers the copied bytes
// with MemoryReport under module "map".
Status load_map_image(const std::uint8_t* bytes, std::size_t size, StartupArena& arena, GlobalMap* out,
                      const char* name = "map image", const MapLoadOptions& options = MapLoadOptions{});

// Arena bytes load_map_image needs at its peak for this image (the kept arrays, the distance check's
// dense field and scratch, alignment padding); 0 when the structure, the geometry or the distance
// section is malformed.
std::size_t map_image_arena_bytes(const std::uint8_t* bytes, std::size_t size,
                                  const MapLoadOptions& options = MapLoadOptions{});

// Payload of the first section of `type`, or nullptr (absent, or header/table malformed). Checks only
// the structure (bounds), not the CRCs: call it on an image load_map_image/verify_map_image accepted.
const std::uint8_t* find_section(const std::uint8_t* bytes, std::size_t size, MapSectionType type,
                                 std::size_t* len, std::uint32_t* section_version = nullptr);

// Table entry i (structure-checked); false when out of range or malformed.
bool map_section_info(const std::uint8_t* bytes, std::size_t size, std::size_t i, MapSectionInfo* info);
std::size_t map_section_count(const std::uint8_t* bytes, std::size_t size);

}  // namespace fw
