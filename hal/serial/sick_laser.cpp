#include "hal_serial/sick_laser.h"

#include <cstdio>

namespace hal_serial {

void SickLaser::init(hal::SerialPort* port, const hal::Clock* clock, const SickLaserOptions& options) {
  port_ = port;
  clock_ = clock;
  options_ = options;
  parser_.reset();
  has_scan_ = false;
}

bool SickLaser::start() {
  if (!port_) return false;
  if (!options_.request_continuous) return true;
  const std::uint8_t payload[2] = {kCmdModeChange, kModeContinuousAll};
  std::uint8_t t[16];
  const std::size_t n = encode_sick_telegram(kHostAddress, payload, sizeof(payload), t, sizeof(t));
  return port_->write(t, n) == static_cast<long>(n);
}

bool SickLaser::restart() {
  parser_.reset();
  has_scan_ = false;
  ++stats_.restarts;
  return start();
}

std::uint32_t SickLaser::fault_bits() const {
  if (port_ != nullptr && !port_->connected()) return static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected);
  return 0;
}

void SickLaser::describe_handshake(char* out, std::size_t cap) const {
  std::snprintf(out, cap, "continuous output requested; %u telegrams, %u CRC errors so far", parser_.stats().telegrams,
                parser_.stats().crc_errors);
}

SerialLaserCounters SickLaser::counters() const {
  SerialLaserCounters c;
  c.scans = stats_.scans;
  c.checksum_errors = parser_.stats().crc_errors;
  c.bad_measurements = stats_.bad_measurements;
  c.dropped = parser_.stats().bad_length;
  return c;
}

void SickLaser::convert(const MeasuredValues& v, std::uint64_t t_ns) {
  hal::LaserScan& s = scan_;
  const std::uint32_t n = v.count;
  s.timestamp_ns = t_ns;
  s.scan_id = next_id_++;
  s.beam_count = n > hal::LaserScan::kMaxBeams ? hal::LaserScan::kMaxBeams : n;
  const float half = 0.5f * options_.fov_rad;
  s.angle_min = -half;
  s.angle_increment = (n % 2 == 1 && n > 1) ? options_.fov_rad / static_cast<float>(n - 1)
                                            : options_.fov_rad / static_cast<float>(n);
  s.range_min = 0.01f;
  const float unit = v.unit_mm ? 0.001f : 0.01f;
  s.range_max = v.unit_mm ? static_cast<float>(kSickNoReturn) * 0.001f : options_.range_max_m;
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    s.ranges[i] = v.values[i] >= kSickNoReturn ? s.range_max : static_cast<float>(v.values[i]) * unit;
  }
}

bool SickLaser::poll(hal::LaserScan* out) {
  if (!port_) return false;
  // Bounded work per call: at most a few reads, then parse what arrived. A port that is gone is
  // not read (the board reopens it; no error is counted per poll meanwhile).
  for (int i = 0; i < 8 && port_->connected(); ++i) {
    const long n = port_->read(rx_, sizeof(rx_));
    if (n < 0) {
      ++stats_.read_errors;
      break;
    }
    if (n == 0) break;
    std::size_t off = 0;
    while (off < static_cast<std::size_t>(n)) {
      off += parser_.feed(rx_ + off, static_cast<std::size_t>(n) - off);
      while (parser_.next(&telegram_)) {
        if (telegram_.command == kRespMeasuredValues) {
          if (decode_measured_values(telegram_, &values_).is_ok()) {
            if (has_scan_) ++stats_.overwritten;
            convert(values_, clock_ ? clock_->now_ns() : 0);
            has_scan_ = true;
            ++stats_.scans;
          } else {
            ++stats_.bad_measurements;
          }
        } else if (telegram_.command == kRespModeChange) {
          ++stats_.mode_acks;
        } else {
          ++stats_.other_telegrams;
        }
      }
    }
  }
  if (!has_scan_) return false;
  *out = scan_;
  has_scan_ = false;
  return true;
}

}  // namespace hal_serial
