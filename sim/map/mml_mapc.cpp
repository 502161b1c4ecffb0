// mml-mapc: compile a ROS map (PGM+YAML) into the firmware's map image, or inspect an image.
//   mml-mapc [--relation-table [--seed N] [--preset C]] MAP.yaml OUT.mmap
//                                   compile (and verify by loading it with the firmware loader);
//                                   --relation-table appends pRANSAM's precomputed global table
//                                   (Sec. 5.5.2) for mmlfw's `seed`/`mml_preset`, so the robot
//                                   skips filling it at start-up
//   mml-mapc --info IMAGE.mmap      validate with the firmware loader and print the section table
// Inputs must be regular files (a FIFO, device or directory is an error naming it); OUT is written
// only after the image passed the firmware loader, through a temporary file renamed over it.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "sim/map/map_image_writer.h"
#include "sim/map/relation_table_builder.h"
#include "sim/common/cli_main.h"

namespace {

const char kUsage[] =
    "usage: mml-mapc [--relation-table [--seed N] [--preset 1..4]] MAP.yaml OUT.mmap\n"
    "       mml-mapc --info IMAGE.mmap\n"
    "Compiles a ROS map_server map (YAML + PGM, e.g. from mml-mapbuild) into the firmware's map image\n"
    "(for mmlfw's `map = OUT.mmap` and mml-sim --map OUT.mmap), verified by the firmware's own loader.\n"
    "  --relation-table   append pRANSAM's precomputed global relation table, so the robot (and mml-sim)\n"
    "                     skips filling it at start-up; it must match mmlfw's `seed` and `mml_preset`\n"
    "  --seed N           seed of the table (default 1)   --preset 1..4   MML configuration (default 3)\n"
    "  --info IMAGE.mmap  validate an image and print its section table\n";

int usage() {
  std::fputs(kUsage, stderr);
  return 2;
}

// Loads with the firmware loader (same code as on the robot: every check, the distance field
// recomputed) into an arena of the size the firmware would need.
bool check_image(const std::string& path, const std::vector<std::uint8_t>& bytes, fw::StartupArena* arena,
                 fw::GlobalMap* map, double* load_ms) {
  const std::size_t need = fw::map_image_arena_bytes(bytes.data(), bytes.size());
  fw::Status st = arena->init_mapped(need > 0 ? need : 4096, false, "mml-mapc");
  const auto t0 = std::chrono::steady_clock::now();
  if (st) st = fw::load_map_image(bytes.data(), bytes.size(), *arena, map, path.c_str());
  *load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!st) {
    std::fprintf(stderr, "mml-mapc: %s\n", st.message());
    return false;
  }
  return true;
}

void print_summary(const std::string& path, const std::vector<std::uint8_t>& bytes, const fw::GlobalMap& map,
                   const fw::StartupArena& arena, double load_ms) {
  const fw::GridGeometry& g = map.geometry;
  std::printf("%s: %zu bytes, version %u\n", path.c_str(), bytes.size(), fw::kMapImageVersion);
  std::printf("  verified and loaded by the firmware loader in %.1f ms (arena peak %zu bytes)\n", load_ms,
              arena.peak_used());
  std::printf("  grid %ux%u at %.4g m, origin (%.4f, %.4f), extent %.1f x %.1f m\n", g.width, g.height,
              static_cast<double>(g.resolution), static_cast<double>(g.origin_x), static_cast<double>(g.origin_y),
              static_cast<double>(g.size_x()), static_cast<double>(g.size_y()));
  std::printf("  occupied points %u, max distance %.3f m\n", map.num_points, static_cast<double>(map.max_distance_m));
  const std::size_t n = fw::map_section_count(bytes.data(), bytes.size());
  for (std::size_t i = 0; i < n; ++i) {
    fw::MapSectionInfo s;
    if (!fw::map_section_info(bytes.data(), bytes.size(), i, &s)) continue;
    std::printf("  section %zu: %-18s v%u offset %10llu size %10llu crc 0x%08x\n", i, fw::map_section_name(s.type),
                s.version, static_cast<unsigned long long>(s.offset), static_cast<unsigned long long>(s.size), s.crc);
  }
}

}  // namespace

bool parse_u64(const char* text, std::uint64_t lo, std::uint64_t hi, std::uint64_t* out) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0' || text[0] == '-' || v < lo || v > hi) return false;
  *out = v;
  return true;
}

static int run_main(int argc, char** argv) {
  std::string err;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  if (argc >= 2 && std::strcmp(argv[1], "--info") == 0 && argc != 3) {
    std::fprintf(stderr, "mml-mapc: --info needs exactly one IMAGE.mmap\n");
    return usage();
  }
  if (argc == 3 && std::strcmp(argv[1], "--info") == 0) {
    std::vector<std::uint8_t> bytes;
    if (!sim::read_file_bytes(argv[2], &bytes, &err)) {
      std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
      return 1;
    }
    fw::StartupArena arena;
    fw::GlobalMap map;
    double ms = 0;
    if (!check_image(argv[2], bytes, &arena, &map, &ms)) return 1;
    print_summary(argv[2], bytes, map, arena, ms);
    return 0;
  }
  bool table = false;
  sim::RelationTableBuild build;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    std::uint64_t v = 0;
    if (a == "--relation-table") {
      table = true;
    } else if (a == "--seed" || a == "--preset") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "mml-mapc: %s needs a value\n", a.c_str());
        return usage();
      }
      const bool ok = a == "--seed" ? parse_u64(argv[i + 1], 0, 0x7FFFFFFF, &v) : parse_u64(argv[i + 1], 1, 4, &v);
      if (!ok) {
        std::fprintf(stderr, "mml-mapc: %s '%s' is not %s\n", a.c_str(), argv[i + 1],
                     a == "--seed" ? "a non-negative integer" : "a configuration 1..4");
        return 2;
      }
      if (a == "--seed") build.seed = v; else build.preset = static_cast<int>(v);
      ++i;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "mml-mapc: unknown option '%s'\n", a.c_str());
      return usage();
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 2) {
    std::fprintf(stderr, "mml-mapc: need MAP.yaml and OUT.mmap (got %zu file arguments)\n", files.size());
    return usage();
  }
  sim::RosMap map;
  sim::MapImageWriter writer;
  if (!sim::read_ros_map(files[0], &map, &err) || !writer.set_map(map, &err)) {
    std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
    return 1;
  }
  if (table) {
    sim::RelationTableBuildReport rep;
    if (!sim::add_relation_table(&writer, build, files[0], &rep, &err)) {
      std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
      return 1;
    }
    std::printf("relation table: %llu triples over %u points (seed %llu, C%d) in %.2f s, %zu bytes\n",
                static_cast<unsigned long long>(rep.triples), rep.map_points,
                static_cast<unsigned long long>(build.seed), build.preset, rep.seconds, rep.section_bytes);
  }
  // Verified before anything is written, then written to a temporary file renamed over OUT: a compile
  // that fails at any point leaves no output (and an older OUT untouched).
  const std::vector<std::uint8_t> bytes = writer.bytes();
  fw::StartupArena arena;
  fw::GlobalMap loaded;
  double ms = 0;
  if (!check_image(files[1], bytes, &arena, &loaded, &ms)) {
    std::fprintf(stderr, "mml-mapc: %s not written\n", files[1].c_str());
    return 1;
  }
  if (!sim::write_file_bytes(files[1], bytes, &err)) {
    std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
    return 1;
  }
  print_summary(files[1], bytes, loaded, arena, ms);
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-mapc", [&] { return run_main(argc, argv); });
}
