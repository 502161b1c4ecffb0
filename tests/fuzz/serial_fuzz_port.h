// What the serial laser harnesses share: the fuzz input's byte stream handed out in chunks as a
// serial port would, a clock the input moves, and the oracle for a delivered scan.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hal/clock.h"
#include "hal/msg/laser_scan.h"
#include "hal/serial_port.h"

namespace fuzz {

inline void serial_check(bool ok, const char* target, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "%s: %s\n", target, what);
    std::abort();
  }
}

class StreamPort final : public hal::SerialPort {
 public:
  std::vector<std::uint8_t> pending;
  std::size_t chunk = 64;
  bool up = true;
  long read(std::uint8_t* buf, std::size_t len) override {
    std::size_t n = std::min({pending.size(), len, chunk});
    std::copy(pending.begin(), pending.begin() + static_cast<long>(n), buf);
    pending.erase(pending.begin(), pending.begin() + static_cast<long>(n));
    return static_cast<long>(n);
  }
  long write(const std::uint8_t*, std::size_t len) override { return static_cast<long>(len); }
  bool connected() const override { return up; }
};

class InputClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return t; }
  std::uint64_t t = 1'000'000'000;
};

// Every scan a driver delivers is one the localizer can use.
inline void check_delivered_scan(const hal::LaserScan& s, const char* target) {
  serial_check(s.beam_count >= 1 && s.beam_count <= hal::LaserScan::kMaxBeams, target, "delivered scan: beam count");
  serial_check(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && s.angle_increment > 0.0f, target,
               "delivered scan: angles");
  serial_check(std::isfinite(s.range_max) && s.range_max > s.range_min && s.range_min >= 0.0f, target,
               "delivered scan: limits");
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    serial_check(std::isfinite(s.ranges[i]) && s.ranges[i] >= 0.0f && s.ranges[i] <= s.range_max, target,
                 "delivered scan: reading");
  }
}

}  // namespace fuzz
