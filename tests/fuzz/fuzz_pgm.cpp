// libFuzzer target: the PGM reader (sim/io/ros_map.cpp read_pgm, P2 and P5) on any file. Oracle:
// an accepted image has width × height pixels, none above maxval, and survives write_pgm →
// read_pgm unchanged.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim/io/ros_map.h"
#include "tests/fuzz/scratch_dir.h"

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_pgm: %s\n", what);
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fuzz::ScratchDir& dir = fuzz::ScratchDir::instance();
  const std::string path = dir.write("in.pgm", data, size);
  sim::RosMap m;
  std::string error;
  if (!sim::read_pgm(path, &m, &error)) {
    check(!error.empty(), "failure without an error message");
    return 0;
  }
  check(m.width > 0 && m.height > 0 && m.pixels.size() == std::size_t(m.width) * std::size_t(m.height),
        "pixel count differs from the header");
  check(m.maxval >= 1 && m.maxval <= 255, "maxval out of range");
  for (std::uint8_t p : m.pixels) check(p <= m.maxval, "pixel above maxval");
  const std::string out = dir.path("out.pgm");
  check(sim::write_pgm(out, m, &error), "write_pgm refused an image read_pgm accepted");
  sim::RosMap back;
  check(sim::read_pgm(out, &back, &error), "read_pgm refused what write_pgm wrote");
  check(back.width == m.width && back.height == m.height && back.maxval == m.maxval && back.pixels == m.pixels,
        "round trip changed the image");
  return 0;
}
