// SickLaser: LMS2xx driver over any hal::SerialPort. Requests continuous output of all measured
// values (mode change 0x20 0x24), parses telegrams with SickParser and turns each 0xB0 telegram
// into a hal::LaserScan (receive time from the HAL clock). Geometry follows the configured field
// of view: n values over 180° (n odd: both ends included, e.g. 181 → 1°, 361 → 0.5°; n even:
// π/n spacing from -π/2, the CARMEN FLASER convention of the logs in ../shared/data).
#pragma once

#include <cstdint>

#include "hal/clock.h"
#include "hal/sensor_io.h"
#include "hal/serial_port.h"
#include "hal_serial/serial_laser.h"
#include "hal_serial/sick_telegram.h"

namespace hal_serial {

struct SickLaserOptions {
  float fov_rad = 3.14159265f;
  float range_max_m = 81.91f;     // cm mode: 0x1FFF cm; readings at 0x1FFF are "no return"
  bool request_continuous = true; // send 0x20 0x24 on start()
};

struct SickLaserStats {
  std::uint32_t scans = 0;
  std::uint32_t bad_measurements = 0;  // CRC-valid 0xB0 telegrams with impossible content (→ HEALTH invalid_scans)
  std::uint32_t other_telegrams = 0;   // responses we do not use (0xA0 acknowledges our request)
  std::uint32_t mode_acks = 0;
  std::uint32_t overwritten = 0;       // scans replaced before the loop took them
  std::uint32_t read_errors = 0;
  std::uint32_t restarts = 0;          // restart() after the port was reopened
};

class SickLaser final : public SerialLaser {
 public:
  void init(hal::SerialPort* port, const hal::Clock* clock, const SickLaserOptions& options);
  // Sends the request for continuous output (if configured). False if the write failed.
  bool start() override;
  // After the port was reopened (the scanner or its cable came back): forgets the partial
  // telegram of the old connection and requests continuous output again.
  bool restart() override;
  // The LMS2xx streams once asked (its 0xA0 acknowledgement is counted, not awaited: a scanner
  // already streaming never sends one), so there is no start-up handshake to wait for.
  bool ready() const override { return true; }
  void describe_handshake(char* out, std::size_t cap) const override;
  SerialLaserCounters counters() const override;
  const char* protocol_name() const override { return "sick"; }
  bool poll(hal::LaserScan* out) override;
  // laser-disconnected while the port is gone; CRC-valid telegrams with impossible content.
  std::uint32_t fault_bits() const override;
  std::uint32_t invalid_scans() const override { return stats_.bad_measurements; }
  std::uint32_t skipped_scans() const override { return stats_.overwritten; }
  const SickParserStats& parser_stats() const { return parser_.stats(); }
  const SickLaserStats& stats() const { return stats_; }

 private:
  void convert(const MeasuredValues& v, std::uint64_t t_ns);
  hal::SerialPort* port_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  SickLaserOptions options_;
  SickParser parser_;
  SickTelegram telegram_;
  MeasuredValues values_;
  hal::LaserScan scan_;
  bool has_scan_ = false;
  std::uint32_t next_id_ = 0;
  SickLaserStats stats_;
  std::uint8_t rx_[1024] = {};
};

}  // namespace hal_serial
