#include "firmware/map/map_image.h"

#include <cmath>
#include <cstring>

#include "firmware/base/crc32.h"
#include "firmware/base/memory_report.h"
#include "firmware/map/edt.h"
#include "firmware/map/le_fields.h"

// The format is little-endian; bulk arrays are copied with memcpy, so the host must be too (x86-64,
// aarch64 and armhf all are). A big-endian port would add byte swapping here.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "map image loader assumes a little-endian CPU");

namespace fw {
namespace {

// Header + table structure (no CRCs). On success *count is the section count.
Status check_structure(const std::uint8_t* bytes, std::size_t size, const char* name, std::size_t* count) {
  if (bytes == nullptr) return Status::error(Errc::kInvalidArgument, "%s: no data", name);
  if (size < kMapImageHeaderBytes) {
    return Status::error(Errc::kCorruptData, "%s: truncated: %zu bytes, header needs %zu", name, size,
                         kMapImageHeaderBytes);
  }
  if (std::memcmp(bytes, kMapImageMagic, sizeof(kMapImageMagic)) != 0) {
    return Status::error(Errc::kCorruptData, "%s: bad magic (not a compiled map image)", name);
  }
  const std::uint32_t version = read_le_u32(bytes + 8);
  if (version != kMapImageVersion) {
    return Status::error(Errc::kUnsupported, "%s: format version %u, this firmware reads version %u", name,
                         version, kMapImageVersion);
  }
  const std::uint64_t total = read_le_u64(bytes + 16);
  if (total != size) {
    return Status::error(Errc::kCorruptData, "%s: header says %llu bytes, got %zu (truncated or padded)", name,
                         static_cast<unsigned long long>(total), size);
  }
  const std::uint32_t n = read_le_u32(bytes + 12);
  if (n > kMaxMapSections) {
    return Status::error(Errc::kCorruptData, "%s: %u sections, at most %zu allowed", name, n, kMaxMapSections);
  }
  const std::size_t table_end = kMapImageHeaderBytes + static_cast<std::size_t>(n) * kMapSectionEntryBytes;
  if (table_end > size) {
    return Status::error(Errc::kCorruptData, "%s: section table (%u entries) runs past the end", name, n);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint8_t* e = bytes + kMapImageHeaderBytes + i * kMapSectionEntryBytes;
    const std::uint64_t off = read_le_u64(e + 8);
    const std::uint64_t len = read_le_u64(e + 16);
    const std::uint32_t type = read_le_u32(e);
    if (off < table_end || off > size || len > size - off) {
      return Status::error(Errc::kCorruptData, "%s: section %u (%s) [offset %llu, %llu bytes] outside the image", name,
                           i, map_section_name(static_cast<MapSectionType>(type)), static_cast<unsigned long long>(off),
                           static_cast<unsigned long long>(len));
    }
    for (std::uint32_t j = 0; j < i; ++j) {
      const std::uint8_t* f = bytes + kMapImageHeaderBytes + j * kMapSectionEntryBytes;
      const std::uint64_t off2 = read_le_u64(f + 8);
      const std::uint64_t len2 = read_le_u64(f + 16);
      if (len > 0 && len2 > 0 && off < off2 + len2 && off2 < off + len) {
        return Status::error(Errc::kCorruptData, "%s: sections %u and %u overlap", name, j, i);
      }
    }
  }
  *count = n;
  return Status::ok();
}

MapSectionInfo entry(const std::uint8_t* bytes, std::size_t i) {
  const std::uint8_t* e = bytes + kMapImageHeaderBytes + i * kMapSectionEntryBytes;
  MapSectionInfo s;
  s.type = static_cast<MapSectionType>(read_le_u32(e));
  s.version = read_le_u32(e + 4);
  s.offset = read_le_u64(e + 8);
  s.size = read_le_u64(e + 16);
  s.crc = read_le_u32(e + 24);
  return s;
}

// The single section of `type` (validated image); error when missing or duplicated.
Status required_section(const std::uint8_t* bytes, std::size_t count, MapSectionType type, const char* name,
                        MapSectionInfo* out) {
  bool found = false;
  for (std::size_t i = 0; i < count; ++i) {
    const MapSectionInfo s = entry(bytes, i);
    if (s.type != type) continue;
    if (found) return Status::error(Errc::kCorruptData, "%s: duplicate %s section", name, map_section_name(type));
    *out = s;
    found = true;
  }
  if (!found) return Status::error(Errc::kCorruptData, "%s: missing %s section", name, map_section_name(type));
  if (out->version != 1) {
    return Status::error(Errc::kUnsupported, "%s: %s section version %u, this firmware reads version 1", name,
                         map_section_name(type), out->version);
  }
  return Status::ok();
}

// The parts of the format that carry no data must be zero (map_image.h): each table entry's reserved
// word and every byte not covered by a section (alignment padding). Sections start 16-byte aligned.
// A writer that puts anything there is not one this firmware knows: refuse rather than ignore it.
Status check_reserved_fields(const std::uint8_t* bytes, std::size_t count, const char* name) {
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint8_t* e = bytes + kMapImageHeaderBytes + i * kMapSectionEntryBytes;
    const MapSectionInfo s = entry(bytes, i);
    const std::uint32_t reserved = read_le_u32(e + 28);
    if (reserved != 0) {
      return Status::error(Errc::kCorruptData, "%s: section %zu (%s): reserved field is 0x%08x, must be 0", name, i,
                           map_section_name(s.type), reserved);
    }
    if (s.offset % kMapSectionAlignment != 0) {
      return Status::error(Errc::kCorruptData, "%s: section %zu (%s): offset %llu is not %zu-byte aligned", name, i,
                           map_section_name(s.type), static_cast<unsigned long long>(s.offset), kMapSectionAlignment);
    }
  }
  return Status::ok();
}

// Checked after the section sizes (load_map_image), so that a section shorter than its geometry is
// reported as such rather than as the stray byte it leaves uncovered.
Status check_padding(const std::uint8_t* bytes, std::size_t size, std::size_t count, const char* name) {
  std::uint32_t order[kMaxMapSections];
  for (std::size_t i = 0; i < count; ++i) {
    const MapSectionInfo s = entry(bytes, i);
    // Insertion sort by offset (at most kMaxMapSections entries).
    std::size_t j = i;
    while (j > 0 && entry(bytes, order[j - 1]).offset > s.offset) {
      order[j] = order[j - 1];
      --j;
    }
    order[j] = static_cast<std::uint32_t>(i);
  }
  std::uint64_t pos = kMapImageHeaderBytes + static_cast<std::uint64_t>(count) * kMapSectionEntryBytes;
  for (std::size_t k = 0; k <= count; ++k) {
    const std::uint64_t next = k < count ? entry(bytes, order[k]).offset : size;
    for (std::uint64_t b = pos; b < next; ++b) {
      if (bytes[b] != 0) {
        return Status::error(Errc::kCorruptData, "%s: byte %llu between sections is 0x%02x (padding must be zero)",
                             name, static_cast<unsigned long long>(b), bytes[b]);
      }
    }
    if (k < count) {
      const MapSectionInfo s = entry(bytes, order[k]);
      if (s.offset + s.size > pos) pos = s.offset + s.size;
    }
  }
  return Status::ok();
}

// The distance field is the map's exact EDT (map_image.h). A wrong one passes every CRC and
// plausibility test above yet steers RBSM, MCL and the tracker to wrong poses, so it is recomputed
// here from the occupancy — the same separable transform (edt.h) the host writer uses — into `out`
// (the arena copy, which this fills) and compared cell by cell. Squared distances are integers in
// cells², exact in float below 2^24 (4096 cells), so there the stored metres must be bit-identical to
// sqrt(d²)·resolution on any IEEE CPU; beyond (a wall more than 4096 cells away) the transform itself
// rounds, and a few float ulps (4e-7 relative) are allowed. Scratch: 16 bytes per cell of the longer
// side, taken from the arena and released before returning.
Status recompute_distance_field(const GridGeometry& geometry, const std::uint8_t* occ_bytes,
                                const std::uint8_t* dist_bytes, StartupArena& arena, float* out, const char* name) {
  const std::size_t w = geometry.width, h = geometry.height, cells = w * h;
  const std::size_t n = w > h ? w : h;
  const std::size_t scratch_mark = arena.mark();
  Result<int*> v = arena.allocate_array<int>(n, "map distance check scratch");
  Result<float*> z = v ? arena.allocate_array<float>(n + 1, "map distance check scratch") : Result<float*>(v.status());
  Result<float*> f = z ? arena.allocate_array<float>(n, "map distance check scratch") : z;
  Result<float*> d = f ? arena.allocate_array<float>(n, "map distance check scratch") : f;
  if (!d) {
    arena.rewind(scratch_mark);
    return Status::error(Errc::kCapacityExceeded, "%s: no arena room to verify the distance field: %s", name,
                         d.status().message());
  }
  for (std::size_t i = 0; i < cells; ++i) out[i] = occ_bytes[i] == kCellOccupied ? 0.0f : kEdtInf;
  const EdtScratch scratch{*v, *z, *f, *d, n};
  const std::size_t dims[2] = {h, w};
  squared_edt<2>(out, dims, scratch);
  arena.rewind(scratch_mark);
  constexpr float kExactBelow = 16777216.0f;  // 2^24 cells²
  for (std::size_t i = 0; i < cells; ++i) {
    const float d2 = out[i];
    const float expected = std::sqrt(d2) * geometry.resolution;
    const float stored = read_le_f32(dist_bytes + 4 * i);
    const bool ok = d2 < kExactBelow ? stored == expected : std::fabs(stored - expected) <= 4e-7f * expected;
    if (!ok) {
      return Status::error(Errc::kCorruptData,
                           "%s: distance field cell %zu (x %zu, y %zu) is %.9g m, the occupied cells put it at %.9g m "
                           "(the distance field does not belong to this map)",
                           name, i, i % w, i / w, static_cast<double>(stored), static_cast<double>(expected));
    }
    out[i] = stored;
  }
  return Status::ok();
}

const char* grid_extent_message(GridExtentProblem p) {
  switch (p) {
    case GridExtentProblem::kNone: return "ok";
    case GridExtentProblem::kResolution: return "resolution is outside [0.0001, 1000] m";
    case GridExtentProblem::kOrigin: return "origin is not finite";
    case GridExtentProblem::kReach:
      return "the grid reaches more than 2^19 cells from the world origin, where float coordinates are coarser "
             "than 1/16 of a cell";
  }
  return "invalid";
}

}  // namespace

const char* map_section_name(MapSectionType type) {
  switch (type) {
    case MapSectionType::kGeometry: return "geometry";
    case MapSectionType::kOccupancy: return "occupancy";
    case MapSectionType::kDistanceField: return "distance field";
    case MapSectionType::kOccupiedPoints: return "occupied points";
    case MapSectionType::kRelationTable2D: return "relation table 2D";
    case MapSectionType::kRelationTable3D: return "relation table 3D";
    case MapSectionType::kUser: return "user";
  }
  return "unknown";
}

namespace {
Status verify_except_padding(const std::uint8_t* bytes, std::size_t size, const char* name) {
  std::size_t count = 0;
  FW_RETURN_IF_ERROR(check_structure(bytes, size, name, &count));
  if (read_le_u32(bytes + 24) != 0) {
    return Status::error(Errc::kUnsupported, "%s: unknown header flags 0x%x", name, read_le_u32(bytes + 24));
  }
  FW_RETURN_IF_ERROR(check_reserved_fields(bytes, count, name));
  for (std::size_t i = 0; i < count; ++i) {
    const MapSectionInfo s = entry(bytes, i);
    const std::uint32_t c = crc32(bytes + s.offset, static_cast<std::size_t>(s.size));
    if (c != s.crc) {
      return Status::error(Errc::kCorruptData, "%s: %s section CRC mismatch (stored 0x%08x, computed 0x%08x)", name,
                           map_section_name(s.type), s.crc, c);
    }
  }
  const std::uint8_t zero[4] = {0, 0, 0, 0};
  std::uint32_t c = crc32_update(0u, bytes, 28);
  c = crc32_update(c, zero, 4);
  c = crc32_update(c, bytes + kMapImageHeaderBytes, size - kMapImageHeaderBytes);
  const std::uint32_t stored = read_le_u32(bytes + 28);
  if (c != stored) {
    return Status::error(Errc::kCorruptData, "%s: image CRC mismatch (stored 0x%08x, computed 0x%08x)", name, stored,
                         c);
  }
  return Status::ok();
}

}  // namespace

Status verify_map_image(const std::uint8_t* bytes, std::size_t size, const char* name) {
  FW_RETURN_IF_ERROR(verify_except_padding(bytes, size, name));
  return check_padding(bytes, size, map_section_count(bytes, size), name);
}

namespace {
// The four sections every map image carries (required_section: exactly one of each, version 1).
struct MapSections {
  MapSectionInfo geo, occ, dist, pts;
};

Status find_map_sections(const std::uint8_t* bytes, std::size_t count, const char* name, MapSections* out) {
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kGeometry, name, &out->geo));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kOccupancy, name, &out->occ));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kDistanceField, name, &out->dist));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kOccupiedPoints, name, &out->pts));
  return Status::ok();
}

// The geometry section's contents; everything else in the image is checked against them.
struct MapGeometry {
  GridGeometry grid;
  std::uint32_t num_points = 0;
  float max_distance = 0.0f;
  std::uint64_t cells() const { return static_cast<std::uint64_t>(grid.width) * grid.height; }
};

// Parses the geometry section and checks each field on its own (plausible, representable extent);
// the cross-checks against the other sections come after.
Status read_geometry(const std::uint8_t* bytes, const MapSectionInfo& geo, const char* name, MapGeometry* out) {
  if (geo.size != kMapGeometryBytes) {
    return Status::error(Errc::kCorruptData, "%s: geometry section is %llu bytes, expected %zu", name,
                         static_cast<unsigned long long>(geo.size), kMapGeometryBytes);
  }
  const std::uint8_t* g = bytes + geo.offset;
  GridGeometry geometry;
  geometry.resolution = read_le_f32(g);
  geometry.origin_x = read_le_f32(g + 4);
  geometry.origin_y = read_le_f32(g + 8);
  geometry.width = read_le_u32(g + 12);
  geometry.height = read_le_u32(g + 16);
  const std::uint32_t num_points = read_le_u32(g + 20);
  const float max_distance = read_le_f32(g + 24);
  if (!std::isfinite(geometry.resolution) || !(geometry.resolution > 0.0f)) {
    return Status::error(Errc::kCorruptData, "%s: geometry: resolution %g is not a positive finite number", name,
                         static_cast<double>(geometry.resolution));
  }
  if (!std::isfinite(geometry.origin_x) || !std::isfinite(geometry.origin_y)) {
    return Status::error(Errc::kCorruptData, "%s: geometry: origin is not finite", name);
  }
  if (geometry.width == 0 || geometry.height == 0) {
    return Status::error(Errc::kCorruptData, "%s: geometry: empty grid %ux%u", name, geometry.width, geometry.height);
  }
  if (!std::isfinite(max_distance) || max_distance < 0.0f) {
    return Status::error(Errc::kCorruptData, "%s: geometry: max distance is not a finite non-negative number", name);
  }
  const std::uint32_t geometry_reserved = read_le_u32(g + 28);
  if (geometry_reserved != 0) {
    return Status::error(Errc::kCorruptData, "%s: geometry: reserved field is 0x%08x, must be 0", name,
                         geometry_reserved);
  }
  const GridExtentProblem extent = check_grid_extent(geometry);
  if (extent != GridExtentProblem::kNone) {
    return Status::error(Errc::kCorruptData, "%s: geometry: %s (resolution %g m, origin (%g, %g), %ux%u cells)", name,
                         grid_extent_message(extent), static_cast<double>(geometry.resolution),
                         static_cast<double>(geometry.origin_x), static_cast<double>(geometry.origin_y),
                         geometry.width, geometry.height);
  }
  out->grid = geometry;
  out->num_points = num_points;
  out->max_distance = max_distance;
  return Status::ok();
}

// The data sections must be exactly as large as the geometry says: check_cells and check_points
// index them by the geometry alone.
Status check_section_sizes(const MapSections& sections, const MapGeometry& map_geometry, const char* name) {
  const GridGeometry& geometry = map_geometry.grid;
  const std::uint64_t cells = map_geometry.cells();
  const std::uint32_t num_points = map_geometry.num_points;
  if (sections.occ.size != cells) {
    return Status::error(Errc::kCorruptData, "%s: occupancy section is %llu bytes, geometry %ux%u needs %llu", name,
                         static_cast<unsigned long long>(sections.occ.size), geometry.width, geometry.height,
                         static_cast<unsigned long long>(cells));
  }
  if (sections.dist.size != cells * 4u) {
    return Status::error(Errc::kCorruptData, "%s: distance field section is %llu bytes, geometry %ux%u needs %llu",
                         name, static_cast<unsigned long long>(sections.dist.size), geometry.width, geometry.height,
                         static_cast<unsigned long long>(cells * 4u));
  }
  if (sections.pts.size != static_cast<std::uint64_t>(num_points) * 8u) {
    return Status::error(Errc::kCorruptData, "%s: occupied points section is %llu bytes, %u points need %llu", name,
                         static_cast<unsigned long long>(sections.pts.size), num_points,
                         static_cast<unsigned long long>(num_points) * 8u);
  }
  return Status::ok();
}

// Contents: occupancy codes, distance 0 exactly on occupied cells, finite non-negative elsewhere; the
// occupied cells and the largest distance must agree with the geometry section.
Status check_cells(const MapGeometry& map_geometry, const std::uint8_t* occ_bytes, const std::uint8_t* dist_bytes,
                   const char* name) {
  const std::uint64_t cells = map_geometry.cells();
  std::uint64_t occupied = 0;
  float max_seen = 0.0f;
  for (std::uint64_t i = 0; i < cells; ++i) {
    const std::uint8_t o = occ_bytes[i];
    if (o > kCellOccupied && o != kCellUnknown) {
      return Status::error(Errc::kCorruptData, "%s: occupancy cell %llu has invalid value %u", name,
                           static_cast<unsigned long long>(i), o);
    }
    const float d = read_le_f32(dist_bytes + 4 * i);
    if (!std::isfinite(d) || d < 0.0f) {
      return Status::error(Errc::kCorruptData, "%s: distance field cell %llu is %s", name,
                           static_cast<unsigned long long>(i), std::isnan(d) ? "NaN" : "negative or infinite");
    }
    if ((o == kCellOccupied) != (d == 0.0f)) {
      return Status::error(Errc::kCorruptData, "%s: distance field cell %llu is %g but the cell is %s", name,
                           static_cast<unsigned long long>(i), static_cast<double>(d),
                           o == kCellOccupied ? "occupied" : "not occupied");
    }
    if (o == kCellOccupied) ++occupied;
    if (d > max_seen) max_seen = d;
  }
  if (occupied == 0) {
    return Status::error(Errc::kCorruptData, "%s: the map has no occupied cells (nothing to localize against)", name);
  }
  if (occupied != map_geometry.num_points) {
    return Status::error(Errc::kCorruptData, "%s: geometry says %u occupied points, occupancy has %llu", name,
                         map_geometry.num_points, static_cast<unsigned long long>(occupied));
  }
  if (max_seen != map_geometry.max_distance) {
    return Status::error(Errc::kCorruptData, "%s: geometry max distance %g, distance field max %g", name,
                         static_cast<double>(map_geometry.max_distance), static_cast<double>(max_seen));
  }
  return Status::ok();
}

// Points: one per occupied cell, at its centre, in row-major order. Strictly increasing cell indices
// plus the count check (check_cells) make that a one-to-one map onto the occupied cells (a duplicated
// point would weigh its wall twice in every match and leave another cell without one). "At the centre"
// allows a quarter cell: the writer's float arithmetic may differ from ours in the last bit (fused
// multiply-add on another CPU), and the extent check bounds that bit to 1/16 of a cell.
Status check_points(const GridGeometry& geometry, std::uint32_t num_points, const std::uint8_t* occ_bytes,
                    const std::uint8_t* pts_bytes, const char* name) {
  std::size_t previous_cell = 0;
  const float centre_tolerance = 0.25f * geometry.resolution;
  for (std::uint32_t i = 0; i < num_points; ++i) {
    const float x = read_le_f32(pts_bytes + 8u * i);
    const float y = read_le_f32(pts_bytes + 8u * i + 4);
    std::int32_t cx = 0, cy = 0;
    if (!std::isfinite(x) || !std::isfinite(y) || !geometry.world_to_cell(x, y, &cx, &cy) ||
        occ_bytes[geometry.index(cx, cy)] != kCellOccupied) {
      return Status::error(Errc::kCorruptData, "%s: occupied point %u (%g, %g) is not inside an occupied cell", name, i,
                           static_cast<double>(x), static_cast<double>(y));
    }
    const std::size_t cell = geometry.index(cx, cy);
    if (i > 0 && cell == previous_cell) {
      return Status::error(Errc::kCorruptData, "%s: occupied point %u (%g, %g) duplicates point %u (cell %d, %d)", name,
                           i, static_cast<double>(x), static_cast<double>(y), i - 1, cx, cy);
    }
    if (i > 0 && cell < previous_cell) {
      return Status::error(Errc::kCorruptData,
                           "%s: occupied point %u (%g, %g) is out of row-major order (cell %d, %d comes before the "
                           "previous point's cell): a duplicate or an unsorted list",
                           name, i, static_cast<double>(x), static_cast<double>(y), cx, cy);
    }
    const Point2f c = geometry.cell_center(cx, cy);
    if (!(std::fabs(x - c.x()) <= centre_tolerance && std::fabs(y - c.y()) <= centre_tolerance)) {
      return Status::error(Errc::kCorruptData, "%s: occupied point %u (%g, %g) is not at the centre (%g, %g) of its cell",
                           name, i, static_cast<double>(x), static_cast<double>(y), static_cast<double>(c.x()),
                           static_cast<double>(c.y()));
    }
    previous_cell = cell;
  }
  return Status::ok();
}

// The arena arrays the loaded map keeps (GlobalMap is a view of them).
struct MapArrays {
  std::uint32_t* occ_slots = nullptr;
  std::uint8_t* occ_cells = nullptr;
  std::uint32_t* dist_slots = nullptr;
  std::uint16_t* dist_tiles = nullptr;
  float* dist_table = nullptr;
  Point2f* points = nullptr;
};

// Carves the kept arrays: occupancy tiles, distance tiles, points, in that order (below the distance
// check's scratch, which must stay on top to be released). On failure everything taken here is
// released again.
Status allocate_map_arrays(const OccupancyTilesLayout& occ_layout, const DistanceFieldLayout& layout,
                           std::uint32_t num_points, StartupArena& arena, MapArrays* out) {
  const std::size_t arena_mark = arena.mark();
  Result<std::uint32_t*> occ_slots =
      arena.allocate_array<std::uint32_t>(occ_layout.slot_count(), "map occupancy tiles");
  Result<std::uint8_t*> occ_mem =
      occ_slots ? arena.allocate_array<std::uint8_t>(occ_layout.cell_count(), "map occupancy tiles")
                : Result<std::uint8_t*>(occ_slots.status());
  if (!occ_mem) {
    arena.rewind(arena_mark);
    return occ_mem.status();
  }
  Result<std::uint32_t*> slot_mem = arena.allocate_array<std::uint32_t>(layout.slot_count(), "map distance tiles");
  Result<std::uint16_t*> tile_mem =
      slot_mem ? arena.allocate_array<std::uint16_t>(layout.cell_count(), "map distance tiles")
               : Result<std::uint16_t*>(slot_mem.status());
  Result<float*> table_mem = tile_mem ? arena.allocate_array<float>(layout.table_count(), "map distance tiles")
                                      : Result<float*>(tile_mem.status());
  if (!table_mem) {
    arena.rewind(arena_mark);
    return table_mem.status();
  }
  Result<Point2f*> pts_mem = arena.allocate_array<Point2f>(num_points, "map occupied points");
  if (!pts_mem) {
    arena.rewind(arena_mark);
    return pts_mem.status();
  }
  out->occ_slots = *occ_slots;
  out->occ_cells = *occ_mem;
  out->dist_slots = *slot_mem;
  out->dist_tiles = *tile_mem;
  out->dist_table = *table_mem;
  out->points = *pts_mem;
  return Status::ok();
}

// recompute_distance_field on a dense float field taken from the arena as scratch and released
// before returning (also when the field is wrong; a failed allocation leaves nothing to release).
Status check_distance_field(const MapGeometry& map_geometry, const std::uint8_t* occ_bytes,
                            const std::uint8_t* dist_bytes, StartupArena& arena, const char* name) {
  const std::size_t scratch_mark = arena.mark();
  Result<float*> dist_mem =
      arena.allocate_array<float>(static_cast<std::size_t>(map_geometry.cells()), "map distance check");
  if (!dist_mem) return dist_mem.status();
  const Status field = recompute_distance_field(map_geometry.grid, occ_bytes, dist_bytes, arena, *dist_mem, name);
  arena.rewind(scratch_mark);
  return field;
}

// The kept arrays in the memory report (module "map").
Status register_map_memory(const OccupancyTilesLayout& occ_layout, const DistanceFieldLayout& layout,
                           std::uint32_t num_points) {
  MemoryReport& report = MemoryReport::instance();
  FW_RETURN_IF_ERROR(report.add({"map", "occupancy (tiles)", occ_layout.bytes(), occ_layout.stored_tiles, nullptr}));
  FW_RETURN_IF_ERROR(report.add({"map", "distance field (tiles)", layout.bytes(), layout.stored_tiles, nullptr}));
  FW_RETURN_IF_ERROR(report.add({"map", "occupied points", num_points * sizeof(Point2f), num_points, nullptr}));
  return Status::ok();
}

// Copy into the start-up arena (the image buffer may be unmapped afterwards). Everything is released
// again (rewind) if the distance field turns out wrong: nothing stays allocated for a bad image.
// The distance field is kept truncated and tiled (distance_field.h); the dense float array the
// check recomputes is scratch above everything kept, released before returning.
Status copy_map_to_arena(const MapGeometry& map_geometry, const std::uint8_t* occ_bytes,
                         const std::uint8_t* dist_bytes, const std::uint8_t* pts_bytes, StartupArena& arena,
                         const MapLoadOptions& options, const char* name, GlobalMap* out) {
  const GridGeometry& geometry = map_geometry.grid;
  const std::uint32_t num_points = map_geometry.num_points;
  DistanceFieldLayout layout;
  FW_RETURN_IF_ERROR(plan_distance_field(dist_bytes, geometry.width, geometry.height, geometry.resolution,
                                         options.distance_truncation_m, &layout));
  OccupancyTilesLayout occ_layout;
  FW_RETURN_IF_ERROR(plan_occupancy_tiles(occ_bytes, geometry.width, geometry.height, &occ_layout));
  const std::size_t arena_mark = arena.mark();
  MapArrays arrays;
  FW_RETURN_IF_ERROR(allocate_map_arrays(occ_layout, layout, num_points, arena, &arrays));
  const Status field = check_distance_field(map_geometry, occ_bytes, dist_bytes, arena, name);
  if (!field) {
    arena.rewind(arena_mark);
    return field;
  }
  const DistanceField distance =
      fill_distance_field(layout, dist_bytes, arrays.dist_slots, arrays.dist_tiles, arrays.dist_table);
  const OccupancyTiles occupancy = fill_occupancy_tiles(occ_layout, occ_bytes, arrays.occ_slots, arrays.occ_cells);
  for (std::uint32_t i = 0; i < num_points; ++i) {
    arrays.points[i] = Point2f(read_le_f32(pts_bytes + 8u * i), read_le_f32(pts_bytes + 8u * i + 4));
  }
  FW_RETURN_IF_ERROR(register_map_memory(occ_layout, layout, num_points));

  out->geometry = geometry;
  out->occupancy = occupancy;
  out->distance = distance;
  out->points = arrays.points;
  out->num_points = num_points;
  out->max_distance_m = map_geometry.max_distance;
  return Status::ok();
}

}  // namespace

Status load_map_image(const std::uint8_t* bytes, std::size_t size, StartupArena& arena, GlobalMap* out,
                      const char* name, const MapLoadOptions& options) {
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "%s: no output map", name);
  FW_RETURN_IF_ERROR(verify_except_padding(bytes, size, name));
  const std::size_t count = map_section_count(bytes, size);

  MapSections sections;
  FW_RETURN_IF_ERROR(find_map_sections(bytes, count, name, &sections));
  MapGeometry map_geometry;
  FW_RETURN_IF_ERROR(read_geometry(bytes, sections.geo, name, &map_geometry));
  FW_RETURN_IF_ERROR(check_section_sizes(sections, map_geometry, name));
  FW_RETURN_IF_ERROR(check_padding(bytes, size, count, name));

  const std::uint8_t* occ_bytes = bytes + sections.occ.offset;
  const std::uint8_t* dist_bytes = bytes + sections.dist.offset;
  const std::uint8_t* pts_bytes = bytes + sections.pts.offset;
  FW_RETURN_IF_ERROR(check_cells(map_geometry, occ_bytes, dist_bytes, name));
  FW_RETURN_IF_ERROR(check_points(map_geometry.grid, map_geometry.num_points, occ_bytes, pts_bytes, name));
  return copy_map_to_arena(map_geometry, occ_bytes, dist_bytes, pts_bytes, arena, options, name, out);
}

std::size_t map_image_arena_bytes(const std::uint8_t* bytes, std::size_t size, const MapLoadOptions& options) {
  std::size_t len = 0;
  const std::uint8_t* g = find_section(bytes, size, MapSectionType::kGeometry, &len);
  if (g == nullptr || len != kMapGeometryBytes) return 0;
  const std::uint64_t w = read_le_u32(g + 12), h = read_le_u32(g + 16), points = read_le_u32(g + 20);
  const std::uint64_t cells = w * h, longer = w > h ? w : h;
  // The distance tiles as load_map_image plans them (an absent or short distance section: 0).
  std::size_t dlen = 0;
  const std::uint8_t* d = find_section(bytes, size, MapSectionType::kDistanceField, &dlen);
  if (d == nullptr || dlen != cells * 4) return 0;
  DistanceFieldLayout layout;
  if (!plan_distance_field(d, static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), read_le_f32(g),
                           options.distance_truncation_m, &layout)) {
    return 0;
  }
  // Peak: occupancy tiles + distance tiles + points + the check's dense float field and its scratch
  // (int v, float z/f/d) + alignment of each array.
  std::size_t olen = 0;
  const std::uint8_t* o = find_section(bytes, size, MapSectionType::kOccupancy, &olen);
  if (o == nullptr || olen != cells) return 0;
  OccupancyTilesLayout occ_layout;
  if (!plan_occupancy_tiles(o, static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), &occ_layout)) return 0;
  const std::uint64_t bytes_needed = occ_layout.bytes() + cells * sizeof(float) + layout.bytes() +
                                     points * sizeof(Point2f) + (longer + 1) * 16 + 8 * 16;
  return bytes_needed > static_cast<std::uint64_t>(static_cast<std::size_t>(-1)) ? 0
                                                                                 : static_cast<std::size_t>(bytes_needed);
}

std::size_t map_section_count(const std::uint8_t* bytes, std::size_t size) {
  std::size_t count = 0;
  if (!check_structure(bytes, size, "map image", &count).is_ok()) return 0;
  return count;
}

bool map_section_info(const std::uint8_t* bytes, std::size_t size, std::size_t i, MapSectionInfo* info) {
  std::size_t count = 0;
  if (!check_structure(bytes, size, "map image", &count).is_ok() || i >= count) return false;
  *info = entry(bytes, i);
  return true;
}

const std::uint8_t* find_section(const std::uint8_t* bytes, std::size_t size, MapSectionType type, std::size_t* len,
                                 std::uint32_t* section_version) {
  std::size_t count = 0;
  if (!check_structure(bytes, size, "map image", &count).is_ok()) return nullptr;
  for (std::size_t i = 0; i < count; ++i) {
    const MapSectionInfo s = entry(bytes, i);
    if (s.type != type) continue;
    if (len != nullptr) *len = static_cast<std::size_t>(s.size);
    if (section_version != nullptr) *section_version = s.version;
    return bytes + s.offset;
  }
  return nullptr;
}

}  // namespace fw
