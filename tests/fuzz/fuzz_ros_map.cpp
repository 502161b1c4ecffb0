// libFuzzer target: a ROS map_server map (YAML + PGM, sim/io/ros_map.*) through everything mml-mapc
// does with it: read, validate, convert to the occupancy grid, compile the map image; and the
// firmware must then load what the host tool wrote (compile → load_map_image round trip).
// Input: a u16-length-prefixed YAML text, then the PGM bytes (written as m.pgm beside it).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "sim/io/ros_map.h"
#include "sim/map/map_image_writer.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/scratch_dir.h"

namespace {
void check(bool ok, const char* what, const std::string& detail = "") {
  if (!ok) {
    std::fprintf(stderr, "fuzz_ros_map: %s %s\n", what, detail.c_str());
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static std::vector<std::uint8_t> block(std::size_t(64) << 20);
  fuzz::ByteReader in(data, size);
  const std::vector<std::uint8_t> yaml = in.blob();
  const std::vector<std::uint8_t> pgm = in.rest();
  const fuzz::ScratchDir& dir = fuzz::ScratchDir::instance();
  dir.write("m.pgm", pgm.data(), pgm.size());
  const std::string yaml_path = dir.write("map.yaml", yaml.data(), yaml.size());
  sim::RosMap m;
  std::string error;
  if (!sim::read_ros_map(yaml_path, &m, &error)) {
    check(!error.empty(), "failure without an error message");
    return 0;
  }
  if (!sim::validate_ros_map(m, "fuzz map", &error)) return 0;
  sim::OccupancyGrid grid;
  if (!sim::ros_map_to_grid(m, &grid, &error)) return 0;
  std::vector<std::uint8_t> image;
  if (!sim::compile_map_image(m, &image, &error)) return 0;
  // What the host tool compiled, the firmware must load.
  fw::StartupArena arena;
  check(arena.init(block.data(), block.size(), "fuzz arena").is_ok(), "arena");
  if (fw::map_image_arena_bytes(image.data(), image.size()) > block.size()) return 0;
  fw::GlobalMap map{};
  const fw::Status st = fw::load_map_image(image.data(), image.size(), arena, &map, "compiled fuzz map");
  check(st.is_ok(), "firmware refused the image mml-mapc compiled:", st.message());
  return 0;
}
