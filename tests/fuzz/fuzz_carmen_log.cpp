// libFuzzer target: the CARMEN log reader (sim/io/carmen_log.*) on any text, plain or gzip, and the
// conversion of every scan it accepts to the HAL message. Input: one flags byte (bit 0 skip bad
// lines, bit 1 read through a file so the gzip path and its caps run), then the log. Oracle: an
// accepted scan is finite and converts to a LaserScan within capacity and its own limits.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim/io/carmen_log.h"
#include "tests/fuzz/scratch_dir.h"

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_carmen_log: %s\n", what);
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  sim::CarmenReadOptions opt;
  opt.skip_bad_lines = data[0] & 1;
  opt.max_bytes = std::uint64_t(4) << 20;  // caps small enough for the fuzzer's memory limit
  opt.max_line_bytes = std::size_t(64) << 10;
  sim::CarmenLog log;
  std::string error;
  bool ok = false;
  if (data[0] & 2) {
    const std::string path = fuzz::ScratchDir::instance().write("log.clf", data + 1, size - 1);
    ok = sim::read_carmen_log(path, opt, &log, &error);
  } else {
    ok = sim::parse_carmen_log("fuzz.clf", reinterpret_cast<const char*>(data + 1), size - 1, opt, &log, &error);
  }
  check(ok || !error.empty(), "failure without an error message");
  for (const sim::CarmenScan& s : log.scans) {
    check(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && std::isfinite(s.max_range),
          "accepted scan with non-finite geometry");
    const hal::LaserScan h = sim::to_laser_scan(s, 1000);
    check(h.beam_count <= hal::LaserScan::kMaxBeams, "converted scan beyond capacity");
    for (std::uint32_t i = 0; i < h.beam_count; ++i) {
      check(std::isfinite(h.ranges[i]) && h.ranges[i] >= 0.0f, "converted scan with a bad reading");
    }
  }
  for (const sim::CarmenOdom& o : log.odom) {
    check(std::isfinite(o.pose.x) && std::isfinite(o.pose.y) && std::isfinite(o.pose.theta), "non-finite odometry");
  }
  return 0;
}
