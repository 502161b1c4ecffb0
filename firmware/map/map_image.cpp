#include "firmware/map/map_image.h"

#include <cmath>
#include <cstring>

#include "firmware/base/memory_report.h"
#include "firmware/map/crc32.h"

// The format is little-endian; bulk arrays are copied with memcpy, so the host must be too (x86-64,
// aarch64 and armhf all are). A big-endian port would add byte swapping here.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "map image loader assumes a little-endian CPU");

namespace fw {
namespace {

std::uint32_t rd_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint64_t rd_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(rd_u32(p)) | (static_cast<std::uint64_t>(rd_u32(p + 4)) << 32);
}
float rd_f32(const std::uint8_t* p) {
  const std::uint32_t u = rd_u32(p);
  float f;
  std::memcpy(&f, &u, sizeof(f));
  return f;
}

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
  const std::uint32_t version = rd_u32(bytes + 8);
  if (version != kMapImageVersion) {
    return Status::error(Errc::kUnsupported, "%s: format version %u, this firmware reads version %u", name,
                         version, kMapImageVersion);
  }
  const std::uint64_t total = rd_u64(bytes + 16);
  if (total != size) {
    return Status::error(Errc::kCorruptData, "%s: header says %llu bytes, got %zu (truncated or padded)", name,
                         static_cast<unsigned long long>(total), size);
  }
  const std::uint32_t n = rd_u32(bytes + 12);
  if (n > kMaxMapSections) {
    return Status::error(Errc::kCorruptData, "%s: %u sections, at most %zu allowed", name, n, kMaxMapSections);
  }
  const std::size_t table_end = kMapImageHeaderBytes + static_cast<std::size_t>(n) * kMapSectionEntryBytes;
  if (table_end > size) {
    return Status::error(Errc::kCorruptData, "%s: section table (%u entries) runs past the end", name, n);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint8_t* e = bytes + kMapImageHeaderBytes + i * kMapSectionEntryBytes;
    const std::uint64_t off = rd_u64(e + 8);
    const std::uint64_t len = rd_u64(e + 16);
    const std::uint32_t type = rd_u32(e);
    if (off < table_end || off > size || len > size - off) {
      return Status::error(Errc::kCorruptData, "%s: section %u (%s) [offset %llu, %llu bytes] outside the image", name,
                           i, map_section_name(static_cast<MapSectionType>(type)), static_cast<unsigned long long>(off),
                           static_cast<unsigned long long>(len));
    }
    for (std::uint32_t j = 0; j < i; ++j) {
      const std::uint8_t* f = bytes + kMapImageHeaderBytes + j * kMapSectionEntryBytes;
      const std::uint64_t off2 = rd_u64(f + 8);
      const std::uint64_t len2 = rd_u64(f + 16);
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
  s.type = static_cast<MapSectionType>(rd_u32(e));
  s.version = rd_u32(e + 4);
  s.offset = rd_u64(e + 8);
  s.size = rd_u64(e + 16);
  s.crc = rd_u32(e + 24);
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

Status verify_map_image(const std::uint8_t* bytes, std::size_t size, const char* name) {
  std::size_t count = 0;
  FW_RETURN_IF_ERROR(check_structure(bytes, size, name, &count));
  if (rd_u32(bytes + 24) != 0) {
    return Status::error(Errc::kUnsupported, "%s: unknown header flags 0x%x", name, rd_u32(bytes + 24));
  }
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
  const std::uint32_t stored = rd_u32(bytes + 28);
  if (c != stored) {
    return Status::error(Errc::kCorruptData, "%s: image CRC mismatch (stored 0x%08x, computed 0x%08x)", name, stored,
                         c);
  }
  return Status::ok();
}

Status load_map_image(const std::uint8_t* bytes, std::size_t size, StartupArena& arena, GlobalMap* out,
                      const char* name) {
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "%s: no output map", name);
  FW_RETURN_IF_ERROR(verify_map_image(bytes, size, name));
  const std::size_t count = map_section_count(bytes, size);

  MapSectionInfo geo, occ, dist, pts;
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kGeometry, name, &geo));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kOccupancy, name, &occ));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kDistanceField, name, &dist));
  FW_RETURN_IF_ERROR(required_section(bytes, count, MapSectionType::kOccupiedPoints, name, &pts));

  if (geo.size != kMapGeometryBytes) {
    return Status::error(Errc::kCorruptData, "%s: geometry section is %llu bytes, expected %zu", name,
                         static_cast<unsigned long long>(geo.size), kMapGeometryBytes);
  }
  const std::uint8_t* g = bytes + geo.offset;
  GridGeometry geometry;
  geometry.resolution = rd_f32(g);
  geometry.origin_x = rd_f32(g + 4);
  geometry.origin_y = rd_f32(g + 8);
  geometry.width = rd_u32(g + 12);
  geometry.height = rd_u32(g + 16);
  const std::uint32_t num_points = rd_u32(g + 20);
  const float max_distance = rd_f32(g + 24);
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
  const std::uint64_t cells = static_cast<std::uint64_t>(geometry.width) * geometry.height;
  if (occ.size != cells) {
    return Status::error(Errc::kCorruptData, "%s: occupancy section is %llu bytes, geometry %ux%u needs %llu", name,
                         static_cast<unsigned long long>(occ.size), geometry.width, geometry.height,
                         static_cast<unsigned long long>(cells));
  }
  if (dist.size != cells * 4u) {
    return Status::error(Errc::kCorruptData, "%s: distance field section is %llu bytes, geometry %ux%u needs %llu",
                         name, static_cast<unsigned long long>(dist.size), geometry.width, geometry.height,
                         static_cast<unsigned long long>(cells * 4u));
  }
  if (pts.size != static_cast<std::uint64_t>(num_points) * 8u) {
    return Status::error(Errc::kCorruptData, "%s: occupied points section is %llu bytes, %u points need %llu", name,
                         static_cast<unsigned long long>(pts.size), num_points,
                         static_cast<unsigned long long>(num_points) * 8u);
  }

  // Contents: occupancy codes, distance 0 exactly on occupied cells, finite non-negative elsewhere.
  const std::uint8_t* occ_bytes = bytes + occ.offset;
  const std::uint8_t* dist_bytes = bytes + dist.offset;
  std::uint64_t occupied = 0;
  float max_seen = 0.0f;
  for (std::uint64_t i = 0; i < cells; ++i) {
    const std::uint8_t o = occ_bytes[i];
    if (o > kCellOccupied && o != kCellUnknown) {
      return Status::error(Errc::kCorruptData, "%s: occupancy cell %llu has invalid value %u", name,
                           static_cast<unsigned long long>(i), o);
    }
    const float d = rd_f32(dist_bytes + 4 * i);
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
  if (occupied != num_points) {
    return Status::error(Errc::kCorruptData, "%s: geometry says %u occupied points, occupancy has %llu", name,
                         num_points, static_cast<unsigned long long>(occupied));
  }
  if (max_seen != max_distance) {
    return Status::error(Errc::kCorruptData, "%s: geometry max distance %g, distance field max %g", name,
                         static_cast<double>(max_distance), static_cast<double>(max_seen));
  }
  const std::uint8_t* pts_bytes = bytes + pts.offset;
  for (std::uint32_t i = 0; i < num_points; ++i) {
    const float x = rd_f32(pts_bytes + 8u * i);
    const float y = rd_f32(pts_bytes + 8u * i + 4);
    std::int32_t cx = 0, cy = 0;
    if (!std::isfinite(x) || !std::isfinite(y) || !geometry.world_to_cell(x, y, &cx, &cy) ||
        occ_bytes[geometry.index(cx, cy)] != kCellOccupied) {
      return Status::error(Errc::kCorruptData, "%s: occupied point %u (%g, %g) is not inside an occupied cell", name, i,
                           static_cast<double>(x), static_cast<double>(y));
    }
  }

  // Valid: copy into the start-up arena (the image buffer may be unmapped afterwards).
  Result<std::uint8_t*> occ_mem = arena.allocate_array<std::uint8_t>(static_cast<std::size_t>(cells), "map occupancy");
  if (!occ_mem) return occ_mem.status();
  Result<float*> dist_mem = arena.allocate_array<float>(static_cast<std::size_t>(cells), "map distance field");
  if (!dist_mem) return dist_mem.status();
  Point2f* points = nullptr;
  if (num_points > 0) {
    Result<Point2f*> pts_mem = arena.allocate_array<Point2f>(num_points, "map occupied points");
    if (!pts_mem) return pts_mem.status();
    points = *pts_mem;
  }
  std::memcpy(*occ_mem, occ_bytes, static_cast<std::size_t>(cells));
  std::memcpy(*dist_mem, dist_bytes, static_cast<std::size_t>(cells) * 4u);
  for (std::uint32_t i = 0; i < num_points; ++i) {
    points[i] = Point2f(rd_f32(pts_bytes + 8u * i), rd_f32(pts_bytes + 8u * i + 4));
  }

  MemoryReport& report = MemoryReport::instance();
  FW_RETURN_IF_ERROR(report.add({"map", "occupancy", static_cast<std::size_t>(cells), static_cast<std::size_t>(cells),
                                 nullptr}));
  FW_RETURN_IF_ERROR(report.add({"map", "distance field", static_cast<std::size_t>(cells) * sizeof(float),
                                 static_cast<std::size_t>(cells), nullptr}));
  FW_RETURN_IF_ERROR(report.add({"map", "occupied points", num_points * sizeof(Point2f), num_points, nullptr}));

  out->geometry = geometry;
  out->occupancy = *occ_mem;
  out->distance_m = *dist_mem;
  out->points = points;
  out->num_points = num_points;
  out->max_distance_m = max_distance;
  return Status::ok();
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
