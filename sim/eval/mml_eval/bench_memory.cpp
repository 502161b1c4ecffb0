// bench_memory: the firmware's static memory for every map of the bench (scripts/bench.sh memory →
// build/bench/memory.json), issue 14. For each dataset the full system is built exactly as mmlfw
// builds it (map loaded into one start-up arena, then fw::LocalizationSystem: mml-track, MML preset
// C3, seed 1, 2 workers, the relation table filled at start-up when the image has none), and the
// footprint is the arena's peak (the map loader's distance check is start-up scratch, so the arena
// must hold its peak) + the relation table kept from the image (when one is in use) + the static
// objects. Per module (MemoryReport) and per map: known area (cells not unknown), bounding box, and
// the growth of the footprint with the known area, a least-squares line over the maps:
// footprint ≈ fixed + slope · area (slope in MiB per 1000 m²). Limit: 64 MiB per map
// (footprint_limit_mib; the run fails when a map exceeds it).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "firmware/app/system.h"
#include "firmware/base/arena.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/map_image.h"
#include "sim/common/bench_json.h"
#include "sim/common/cli_main.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"

namespace {

constexpr double kMiB = 1024.0 * 1024.0;
constexpr double kLimitMiB = 64.0;

struct MapFigures {
  std::string name, key;
  double footprint_mib = 0, known_area_m2 = 0, bbox_area_m2 = 0;
  double arena_peak_mib = 0, arena_used_mib = 0, table_copy_mib = 0, statics_mib = 0;
  std::map<std::string, double> module_mib;
  std::uint32_t tiles_stored = 0, tiles_total = 0;
  double truncation_m = 0;
};

std::string json_key(std::string s) {
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

bool measure(const std::string& name, fw::WorkerPool* pool, MapFigures* out, std::string* err) {
  sim::RosMap ros;
  if (!sim::ensure_global_map(name, -1.0, sim::map_cache_dir(), &ros, err)) return false;
  std::vector<std::uint8_t> image;
  if (!sim::read_file_bytes(sim::global_map_image_path(name), &image, err)) return false;

  fw::MemoryReport::instance().clear();
  // One arena for the map and the system, as mmlfw (its size is only an upper bound; the figures
  // are what was used).
  fw::StartupArena arena;
  fw::Status st = arena.init_mapped(std::size_t(512) << 20, false, "arena");
  fw::GlobalMap map;
  if (st) st = fw::load_map_image(image.data(), image.size(), arena, &map, name.c_str());
  if (!st) {
    *err = name + ": " + st.message();
    return false;
  }
  std::size_t table_len = 0;
  const std::uint8_t* table =
      fw::find_section(image.data(), image.size(), fw::MapSectionType::kRelationTable2D, &table_len);
  fw::LocalizationSystem system;
  fw::SystemSpec spec;  // mml-track, preset C3, seed 1: the shipped configuration
  st = system.build(spec, map, table, table_len, arena, pool);
  if (!st) {
    *err = name + ": system: " + st.message();
    return false;
  }
  arena.seal();

  MapFigures& f = *out;
  f.name = name;
  f.key = json_key(name);
  const fw::GridGeometry& g = map.geometry;
  std::size_t known = 0;
  for (std::uint32_t y = 0; y < g.height; ++y) {
    for (std::uint32_t x = 0; x < g.width; ++x) {
      known += map.cell(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y)) != fw::kCellUnknown;
    }
  }
  const double cell_area = static_cast<double>(g.resolution) * static_cast<double>(g.resolution);
  f.known_area_m2 = static_cast<double>(known) * cell_area;
  f.bbox_area_m2 = static_cast<double>(g.cell_count()) * cell_area;
  f.arena_used_mib = static_cast<double>(arena.used()) / kMiB;
  f.arena_peak_mib = static_cast<double>(std::max(arena.peak_used(), arena.used())) / kMiB;
  f.table_copy_mib = system.table_in_use() ? static_cast<double>(table_len) / kMiB : 0.0;
  // The firmware's static objects besides the arena (mmlfw: board, loop, pool, system; the board's
  // and the loop's ~0.13 MiB are not built here, so the system object and the pool stand for them).
  f.statics_mib = static_cast<double>(sizeof(fw::LocalizationSystem) + sizeof(fw::WorkerPool)) / kMiB;
  f.footprint_mib = f.arena_peak_mib + f.table_copy_mib + f.statics_mib;
  const fw::MemoryReport& mr = fw::MemoryReport::instance();
  for (std::size_t i = 0; i < mr.region_count(); ++i) {
    const fw::MemoryRegion& r = mr.region(i);
    if (std::strcmp(r.module, "arena") == 0) continue;
    f.module_mib[r.module] += static_cast<double>(r.bytes) / kMiB;
  }
  f.tiles_stored = map.distance.stored_tiles;
  f.tiles_total = map.distance.tiles_x * map.distance.tiles_y;
  f.truncation_m = map.distance.truncation_m;
  return true;
}

int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_memory OUTPUT.json\n");
    return 2;
  }
  fw::WorkerPool pool;
  fw::WorkerPoolOptions po;
  po.num_workers = 2;
  const fw::Status ps = pool.start(po);
  if (!ps) {
    std::fprintf(stderr, "bench_memory: workers: %s\n", ps.message());
    return 1;
  }
  sim::BenchJson json;
  std::vector<MapFigures> maps;
  for (const std::string& name : sim::global_map_datasets()) {
    std::printf("bench_memory: %s ...\n", name.c_str());
    std::fflush(stdout);
    MapFigures f;
    std::string err;
    if (!measure(name, &pool, &f, &err)) {
      std::fprintf(stderr, "bench_memory: %s\n", err.c_str());
      pool.stop();
      return 1;
    }
    std::printf("  %-12s footprint %7.2f MiB (arena peak %.2f, used %.2f), known area %.0f m² of a %.0f m² box, "
                "distance tiles %u of %u (truncation %.2f m)\n",
                name.c_str(), f.footprint_mib, f.arena_peak_mib, f.arena_used_mib, f.known_area_m2, f.bbox_area_m2,
                f.tiles_stored, f.tiles_total, f.truncation_m);
    for (const auto& [module, mib] : f.module_mib) std::printf("    %-10s %8.3f MiB\n", module.c_str(), mib);
    maps.push_back(f);
  }
  pool.stop();

  double max_fp = 0;
  std::string max_name;
  bool over = false;
  for (const MapFigures& f : maps) {
    json.add(f.key + "_footprint_mib", f.footprint_mib);
    json.add(f.key + "_arena_peak_mib", f.arena_peak_mib);
    json.add(f.key + "_arena_used_mib", f.arena_used_mib);
    json.add(f.key + "_known_area_m2", f.known_area_m2);
    json.add(f.key + "_bbox_area_m2", f.bbox_area_m2);
    for (const auto& [module, mib] : f.module_mib) json.add(f.key + "_" + module + "_mib", mib);
    json.add_int(f.key + "_distance_tiles_stored", f.tiles_stored);
    json.add_int(f.key + "_distance_tiles_total", f.tiles_total);
    if (f.footprint_mib > max_fp) {
      max_fp = f.footprint_mib;
      max_name = f.name;
    }
    over = over || f.footprint_mib > kLimitMiB;
  }
  json.add("footprint_mib_max", max_fp);
  json.add_string("footprint_mib_max_map", max_name);
  json.add("footprint_limit_mib", kLimitMiB);
  json.add("distance_truncation_m", maps.empty() ? 0.0 : maps.front().truncation_m);
  // Growth with the mapped area: least squares footprint = a + b·area over the maps.
  if (maps.size() >= 2) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(maps.size());
    for (const MapFigures& f : maps) {
      const double x = f.known_area_m2 / 1000.0;
      sx += x;
      sy += f.footprint_mib;
      sxx += x * x;
      sxy += x * f.footprint_mib;
    }
    const double den = n * sxx - sx * sx;
    if (den > 0) {
      const double b = (n * sxy - sx * sy) / den, a = (sy - b * sx) / n;
      json.add("footprint_mib_per_1000m2_known", b);
      json.add("footprint_fixed_mib", a);
    }
  }
  if (!json.write(argv[1])) return 1;
  if (over) {
    std::fprintf(stderr, "bench_memory: %s needs %.2f MiB > the %.0f MiB limit\n", max_name.c_str(), max_fp, kLimitMiB);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return sim::guarded_main("bench_memory", [&] { return run_main(argc, argv); });
}
