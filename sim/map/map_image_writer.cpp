#include "sim/map/map_image_writer.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "firmware/map/edt.h"
#include "sim/common/fail.h"
#include "sim/io/file_io.h"

namespace sim {
namespace {

void put_u32(std::vector<std::uint8_t>* b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>* b, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_f32(std::vector<std::uint8_t>* b, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  put_u32(b, u);
}
void set_u32(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void set_u64(std::vector<std::uint8_t>* b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint32_t zcrc(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
  uLong c = crc;
  // zlib takes uInt lengths: feed in chunks.
  while (n > 0) {
    const std::size_t chunk = std::min<std::size_t>(n, 1u << 30);
    c = ::crc32(c, p, static_cast<uInt>(chunk));
    p += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(c);
}

bool is_map_section(fw::MapSectionType t) {
  return t == fw::MapSectionType::kGeometry || t == fw::MapSectionType::kOccupancy ||
         t == fw::MapSectionType::kDistanceField || t == fw::MapSectionType::kOccupiedPoints;
}

}  // namespace

bool distance_field_m(const OccupancyGrid& grid, std::vector<float>* out, std::string* error) {
  const std::size_t w = grid.geometry.width, h = grid.geometry.height;
  if (w == 0 || h == 0 || grid.cells.size() != w * h) return fail(error, "distance field: grid is empty or inconsistent");
  std::vector<float> d(w * h);
  std::size_t occupied = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const bool occ = grid.cells[i] == fw::kCellOccupied;
    d[i] = occ ? 0.0f : fw::kEdtInf;
    occupied += occ ? 1 : 0;
  }
  if (occupied == 0) return fail(error, "distance field: the map has no occupied cells");
  const std::size_t n = std::max(w, h);
  std::vector<int> v(n);
  std::vector<float> z(n + 1), f(n), dd(n);
  const fw::EdtScratch scratch{v.data(), z.data(), f.data(), dd.data(), n};
  const std::size_t dims[2] = {h, w};
  fw::squared_edt<2>(d.data(), dims, scratch);
  const float res = grid.geometry.resolution;
  for (std::size_t i = 0; i < d.size(); ++i) {
    // The firmware loader rejects images where "distance 0" and "occupied" disagree; check here so
    // a bad field is reported when it is made, not when the robot boots.
    if ((d[i] == 0.0f) != (grid.cells[i] == fw::kCellOccupied) || !(d[i] < fw::kEdtInf)) {
      return fail(error, "distance field: EDT inconsistent at cell " + std::to_string(i) + " (squared distance " +
                             std::to_string(d[i]) + ")");
    }
    d[i] = std::sqrt(d[i]) * res;
  }
  *out = std::move(d);
  return true;
}

bool MapImageWriter::set_map(const RosMap& map, std::string* error) {
  OccupancyGrid g;
  if (!ros_map_to_grid(map, &g, error)) return false;
  return set_grid(g, error);
}

bool MapImageWriter::set_grid(const OccupancyGrid& grid, std::string* error) {
  const fw::GridGeometry& geo = grid.geometry;
  if (!std::isfinite(geo.resolution) || !(geo.resolution > 0.0f)) return fail(error, "map image: resolution must be > 0");
  if (!std::isfinite(geo.origin_x) || !std::isfinite(geo.origin_y)) return fail(error, "map image: origin not finite");
  if (fw::check_grid_extent(geo) != fw::GridExtentProblem::kNone) {
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "map image: resolution %g m, origin (%g, %g), %ux%u cells: float coordinates cannot resolve the "
                  "cells (resolution outside [1e-4, 1e3] m or the grid reaching beyond 2^19 cells from the origin)",
                  static_cast<double>(geo.resolution), static_cast<double>(geo.origin_x),
                  static_cast<double>(geo.origin_y), geo.width, geo.height);
    return fail(error, buf);
  }
  if (geo.width == 0 || geo.height == 0 || grid.cells.size() != geo.cell_count()) {
    return fail(error, "map image: grid size inconsistent with its geometry");
  }
  for (std::size_t i = 0; i < grid.cells.size(); ++i) {
    if (grid.cells[i] > 100 && grid.cells[i] != 255) {
      return fail(error, "map image: cell " + std::to_string(i) + " has invalid occupancy " + std::to_string(grid.cells[i]));
    }
  }
  std::vector<float> dist;
  if (!distance_field_m(grid, &dist, error)) return false;
  const std::vector<fw::Point2f> pts = occupied_points(grid);
  float max_d = 0.0f;
  for (float x : dist) max_d = std::max(max_d, x);

  std::vector<std::uint8_t> g;
  put_f32(&g, geo.resolution);
  put_f32(&g, geo.origin_x);
  put_f32(&g, geo.origin_y);
  put_u32(&g, geo.width);
  put_u32(&g, geo.height);
  put_u32(&g, static_cast<std::uint32_t>(pts.size()));
  put_f32(&g, max_d);
  put_u32(&g, 0);
  std::vector<std::uint8_t> dbytes;
  dbytes.reserve(dist.size() * 4);
  for (float x : dist) put_f32(&dbytes, x);
  std::vector<std::uint8_t> pbytes;
  pbytes.reserve(pts.size() * 8);
  for (const fw::Point2f& p : pts) {
    put_f32(&pbytes, p.x());
    put_f32(&pbytes, p.y());
  }
  map_sections_.clear();
  map_sections_.push_back({fw::MapSectionType::kGeometry, 1, std::move(g)});
  map_sections_.push_back({fw::MapSectionType::kOccupancy, 1, grid.cells});
  map_sections_.push_back({fw::MapSectionType::kDistanceField, 1, std::move(dbytes)});
  map_sections_.push_back({fw::MapSectionType::kOccupiedPoints, 1, std::move(pbytes)});
  return true;
}

bool MapImageWriter::add_section(fw::MapSectionType type, std::vector<std::uint8_t> bytes, std::uint32_t version,
                                 std::string* error) {
  if (is_map_section(type)) {
    return fail(error, std::string("map image: section '") + fw::map_section_name(type) + "' is written by set_map/set_grid");
  }
  if (map_sections_.size() + extra_sections_.size() >= fw::kMaxMapSections) {
    return fail(error, "map image: too many sections");
  }
  extra_sections_.push_back({type, version, std::move(bytes)});
  return true;
}

std::vector<std::uint8_t> MapImageWriter::bytes() const {
  std::vector<std::uint8_t> out;
  if (map_sections_.empty()) return out;
  std::vector<const Section*> all;
  for (const Section& s : map_sections_) all.push_back(&s);
  for (const Section& s : extra_sections_) all.push_back(&s);
  out.insert(out.end(), fw::kMapImageMagic, fw::kMapImageMagic + 8);
  put_u32(&out, fw::kMapImageVersion);
  put_u32(&out, static_cast<std::uint32_t>(all.size()));
  put_u64(&out, 0);  // total size, patched below
  put_u32(&out, 0);  // flags
  put_u32(&out, 0);  // image CRC, patched below
  const std::size_t table = out.size();
  out.resize(table + all.size() * fw::kMapSectionEntryBytes, 0);
  for (std::size_t i = 0; i < all.size(); ++i) {
    while (out.size() % fw::kMapSectionAlignment != 0) out.push_back(0);
    const std::size_t off = out.size();
    out.insert(out.end(), all[i]->bytes.begin(), all[i]->bytes.end());
    const std::size_t e = table + i * fw::kMapSectionEntryBytes;
    set_u32(&out, e, static_cast<std::uint32_t>(all[i]->type));
    set_u32(&out, e + 4, all[i]->version);
    set_u64(&out, e + 8, off);
    set_u64(&out, e + 16, all[i]->bytes.size());
    set_u32(&out, e + 24, zcrc(all[i]->bytes.data(), all[i]->bytes.size()));
  }
  set_u64(&out, 16, out.size());
  set_u32(&out, 28, zcrc(out.data(), out.size()));  // CRC field is still zero here
  return out;
}

bool MapImageWriter::write(const std::string& path, std::string* error) const {
  if (map_sections_.empty()) return fail(error, path + ": no map set");
  return write_file_bytes(path, bytes(), error);
}

bool compile_map_image(const RosMap& map, std::vector<std::uint8_t>* out, std::string* error) {
  MapImageWriter w;
  if (!w.set_map(map, error)) return false;
  *out = w.bytes();
  return true;
}

bool read_file_bytes(const std::string& path, std::vector<std::uint8_t>* out, std::string* error) {
  return read_regular_file(path, kMaxMapFileBytes, out, error);
}

bool write_file_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes, std::string* error) {
  return write_file_atomic(path, bytes.data(), bytes.size(), error);
}

}  // namespace sim
