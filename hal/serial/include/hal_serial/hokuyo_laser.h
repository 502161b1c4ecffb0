// HokuyoLaser: Hokuyo URG / UTM / UST driver over SCIP 2.0 (hal_serial/scip.h) on any
// hal::SerialPort (USB-ACM or RS-232). Start-up handshake, one request at a time, each resent when
// not answered within answer_timeout_ms:
//   SCIP2.0 (switches a SCIP 1.1 unit; answer ignored) → QT (stop) → VV (version) → PP (geometry)
//   → II (state) → BM (laser on; "02" already on is fine) → MD or ME (continuous, 3-character
//   encoding, intensity with ME) → streaming of "99" answers.
// Geometry comes from the PP answer, never hard-coded: steps AMIN..AMAX, step angle 2π/ARES,
// front step AFRT; the cluster count is the smallest that fits hal::LaserScan::kMaxBeams (1 for
// every unit of 1081 steps or fewer), and a beam's angle is its cluster's centre. Readings below
// DMIN are the sensor's error codes (no echo, too near, too bright) and, like readings above
// DMAX, become "no return" (range_max = DMAX).
// Time stamps: the 24-bit ms counter is unwrapped (a backwards step of more than half the range
// is a wrap; a smaller one is a device reset and re-anchors) and mapped to the HAL clock by the
// smallest (receipt − sensor time) seen, creeping up 1 µs a scan so a sensor clock slower than
// the host's by up to 40 ppm at 40 Hz is followed: the USB/serial latency jitter does not reach
// the scan time. Without a clock the sensor time itself is the stamp.
// A device that stays silent for silence_restart_ms while streaming (reset, power dip) gets the
// handshake again. Bad lines and impossible answers are counted and dropped.
#pragma once

#include <cstdint>

#include "hal/clock.h"
#include "hal/serial_port.h"
#include "hal_serial/scip.h"
#include "hal_serial/serial_laser.h"

namespace hal_serial {

struct HokuyoOptions {
  bool intensity = false;                   // ME (range + intensity) instead of MD
  std::uint32_t min_cluster = 1;            // cluster count at least this (coarser scans)
  std::uint32_t answer_timeout_ms = 300;    // a handshake request not answered is sent again
  std::uint32_t silence_restart_ms = 1000;  // streaming without a scan this long: handshake again
};

enum class HokuyoState : std::uint8_t { kIdle, kScip2, kQuit, kVersion, kParameters, kStatus, kLaserOn, kRequestScans, kStreaming };
const char* hokuyo_state_name(HokuyoState s);

struct HokuyoStats {
  std::uint32_t scans = 0;
  std::uint32_t bad_measurements = 0;  // intact "99" answers that do not decode or do not match the request
  std::uint32_t device_errors = 0;     // answers with an error status (hardware trouble 50..97, ...)
  std::uint32_t stale_answers = 0;     // answers to an earlier request (e.g. scans after QT)
  std::uint32_t overwritten = 0;
  std::uint32_t read_errors = 0;
  std::uint32_t retries = 0;           // handshake requests sent again after answer_timeout_ms
  std::uint32_t device_restarts = 0;   // handshakes repeated after silence_restart_ms
  std::uint32_t restarts = 0;          // restart() after the port was reopened
  std::uint32_t timestamp_wraps = 0;
  std::uint32_t timestamp_resets = 0;  // the sensor's clock went back (device reset)
};

class HokuyoLaser final : public SerialLaser {
 public:
  void init(hal::SerialPort* port, const hal::Clock* clock, const HokuyoOptions& options);
  bool start() override;
  bool restart() override;
  bool ready() const override { return state_ == HokuyoState::kStreaming; }
  void describe_handshake(char* out, std::size_t cap) const override;
  SerialLaserCounters counters() const override;
  const char* protocol_name() const override { return "hokuyo"; }

  bool poll(hal::LaserScan* out) override;
  std::uint32_t fault_bits() const override;
  std::uint32_t invalid_scans() const override { return stats_.bad_measurements; }
  std::uint32_t skipped_scans() const override { return stats_.overwritten; }

  HokuyoState state() const { return state_; }
  const ScipParameters& parameters() const { return params_; }
  // The VV answer's PROD and FIRM (empty until answered).
  const char* product() const { return product_; }
  const char* firmware() const { return firmware_; }
  const ScipParserStats& parser_stats() const { return parser_.stats(); }
  const HokuyoStats& stats() const { return stats_; }
  // Sensor time of the last scan, unwrapped (ms).
  std::uint64_t last_sensor_time_ms() const { return sensor_ms_; }

 private:
  bool send_request(HokuyoState s);
  void on_answer(const ScipResponse& r);
  void on_handshake_answer(const ScipResponse& r);
  void on_scan_answer(const ScipResponse& r);
  void convert(const ScipScan& s);
  std::uint64_t stamp(std::uint32_t ts_ms);
  void tick();
  std::uint64_t now_ns() const { return clock_ ? clock_->now_ns() : 0; }

  hal::SerialPort* port_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  HokuyoOptions options_;
  ScipParser parser_;
  ScipResponse answer_;
  ScipScan decoded_;
  ScipParameters params_;
  char product_[48] = {0};
  char firmware_[48] = {0};
  char failure_[160] = {0};  // the last handshake answer that was wrong, for describe_handshake
  HokuyoState state_ = HokuyoState::kIdle;
  std::uint32_t first_ = 0, last_ = 0, cluster_ = 1;  // requested steps
  std::uint64_t sent_ns_ = 0;
  std::uint64_t last_scan_ns_ = 0;
  bool have_ts_ = false;
  std::uint32_t last_ts_ = 0;
  std::uint64_t epoch_ms_ = 0;
  std::uint64_t sensor_ms_ = 0;
  bool have_offset_ = false;
  std::int64_t offset_ns_ = 0;  // host time − sensor time (smallest seen, creeping)
  hal::LaserScan scan_;
  bool has_scan_ = false;
  std::uint32_t next_id_ = 0;
  HokuyoStats stats_;
  std::uint8_t rx_[1024] = {};
};

}  // namespace hal_serial
