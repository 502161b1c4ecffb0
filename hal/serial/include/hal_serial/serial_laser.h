// SerialLaser: what the Linux board and mmlfw's summary need of any laser driver on a serial port
// (SICK LMS2xx, Hokuyo SCIP 2.0, Slamtec RPLIDAR), so the board keeps one code path for opening,
// the start-up handshake, losing and reopening the port. Each driver is a non-blocking state
// machine driven by poll(): start() sends its first request, poll() reads, answers and times out.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/sensor_io.h"

namespace hal_serial {

// The same counters for every serial laser (mmlfw summary: serial_scans, serial_crc_errors, ...).
struct SerialLaserCounters {
  std::uint32_t scans = 0;             // scans handed out or replaced (every intact scan)
  std::uint32_t checksum_errors = 0;   // telegrams / lines / packets with a wrong CRC or sum
  std::uint32_t bad_measurements = 0;  // intact but impossible content (→ HEALTH invalid_scans)
  std::uint32_t dropped = 0;           // other input dropped: truncated, malformed, partial revolutions
  std::uint32_t device_restarts = 0;   // handshakes repeated because the device fell silent or reset
};

class SerialLaser : public hal::LaserScanSource {
 public:
  // Sends the first request. False if the write failed.
  virtual bool start() = 0;
  // After the port was reopened: forgets the old connection's partial input and starts again.
  virtual bool restart() = 0;
  // True once the device answered the start-up requests and scans are requested.
  virtual bool ready() const = 0;
  // Why it is not ready (the state, the last answer received), for the start-up error.
  virtual void describe_handshake(char* out, std::size_t cap) const = 0;
  virtual SerialLaserCounters counters() const = 0;
  virtual const char* protocol_name() const = 0;
};

}  // namespace hal_serial
