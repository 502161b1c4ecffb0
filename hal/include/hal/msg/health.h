// Health: counters published in the heartbeat frame.
#pragma once

#include <cstdint>

namespace hal {

struct Health {
  std::uint64_t timestamp_ns = 0;
  std::uint32_t fault_bits = 0;
  std::uint32_t crc_errors = 0;
  std::uint32_t lost_segments = 0;
  std::uint32_t dropped_scans = 0;
  std::uint32_t timeouts = 0;
  std::uint32_t deadline_misses = 0;
  std::uint32_t bus_off_count = 0;
  std::uint32_t scans_processed = 0;
};

}  // namespace hal
