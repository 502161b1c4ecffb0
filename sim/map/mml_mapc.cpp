// mml-mapc: compile a ROS map (PGM+YAML) into the firmware's map image, or inspect an image.
//   mml-mapc MAP.yaml OUT.mmap      compile (and verify by loading it with the firmware loader)
//   mml-mapc --info IMAGE.mmap      validate with the firmware loader and print the section table
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "sim/map/map_image_writer.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: mml-mapc MAP.yaml OUT.mmap\n"
               "       mml-mapc --info IMAGE.mmap\n");
  return 2;
}

// Loads with the firmware loader (same code as on the robot) and prints a summary.
int check_and_print(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  fw::StartupArena arena;
  fw::Status st = arena.init_mapped(bytes.size() + 4096, false, "mml-mapc");
  if (!st) {
    std::fprintf(stderr, "mml-mapc: %s\n", st.message());
    return 1;
  }
  fw::GlobalMap map;
  st = fw::load_map_image(bytes.data(), bytes.size(), arena, &map, path.c_str());
  if (!st) {
    std::fprintf(stderr, "mml-mapc: %s\n", st.message());
    return 1;
  }
  const fw::GridGeometry& g = map.geometry;
  std::printf("%s: %zu bytes, version %u\n", path.c_str(), bytes.size(), fw::kMapImageVersion);
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
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return usage();
  std::string err;
  if (std::strcmp(argv[1], "--info") == 0) {
    std::vector<std::uint8_t> bytes;
    if (!sim::read_file_bytes(argv[2], &bytes, &err)) {
      std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
      return 1;
    }
    return check_and_print(argv[2], bytes);
  }
  sim::RosMap map;
  if (!sim::read_ros_map(argv[1], &map, &err)) {
    std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
    return 1;
  }
  std::vector<std::uint8_t> bytes;
  if (!sim::compile_map_image(map, &bytes, &err) || !sim::write_file_bytes(argv[2], bytes, &err)) {
    std::fprintf(stderr, "mml-mapc: %s\n", err.c_str());
    return 1;
  }
  return check_and_print(argv[2], bytes);
}
