// Health: counters published in the heartbeat frame.
#pragma once

#include <cstdint>

namespace hal {

// Named faults of the sensors and links, bits 16..31 of Health::fault_bits (bits 0..15 are the
// firmware's "cannot happen" bits, fw::Fault in firmware/base/fault.h). These are bad luck, not
// bad programming: the runtime raises one while the condition lasts and clears it when it ends.
enum class HealthFault : std::uint32_t {
  kLaserTimeout = 1u << 16,       // "laser-timeout": no usable scan for the configured laser timeout
  kLaserDisconnected = 1u << 17,  // "laser-disconnected": the laser's port was closed by the peer / vanished;
                                  // the board reopens it with a back-off
};
constexpr std::uint32_t kHealthFaultMask = 0xFFFF0000u;

inline const char* health_fault_name(HealthFault f) {
  switch (f) {
    case HealthFault::kLaserTimeout: return "laser-timeout";
    case HealthFault::kLaserDisconnected: return "laser-disconnected";
  }
  return "unknown";
}

struct Health {
  std::uint64_t timestamp_ns = 0;
  std::uint32_t fault_bits = 0;      // fw::Fault bits | HealthFault bits
  std::uint32_t crc_errors = 0;
  std::uint32_t lost_segments = 0;
  std::uint32_t dropped_scans = 0;
  std::uint32_t timeouts = 0;        // odometry pairing timeouts + laser-timeout episodes
  std::uint32_t deadline_misses = 0;
  std::uint32_t bus_off_count = 0;
  std::uint32_t scans_processed = 0;
  // Scans that arrived intact (checksum right) but with impossible content (CAN: bad geometry;
  // SICK: impossible measured-values telegram), rejected by the laser source.
  std::uint32_t invalid_scans = 0;
  // The last pose hint's verification (hal::HintStatus as u8; HEALTH.HintStatus on CAN).
  std::uint8_t hint_status = 0;
};

}  // namespace hal
