#include "hal_serial/hokuyo_laser.h"

#include <cstdio>
#include <cstring>

namespace hal_serial {

namespace {
constexpr double kTwoPi = 6.283185307179586;
constexpr std::uint64_t kHokuyoNsPerMs = 1000000ull;
}  // namespace

const char* hokuyo_state_name(HokuyoState s) {
  switch (s) {
    case HokuyoState::kIdle: return "idle";
    case HokuyoState::kScip2: return "SCIP2.0";
    case HokuyoState::kQuit: return "QT";
    case HokuyoState::kVersion: return "VV";
    case HokuyoState::kParameters: return "PP";
    case HokuyoState::kStatus: return "II";
    case HokuyoState::kLaserOn: return "BM";
    case HokuyoState::kRequestScans: return "MD";
    case HokuyoState::kStreaming: return "streaming";
  }
  return "?";
}

void HokuyoLaser::init(hal::SerialPort* port, const hal::Clock* clock, const HokuyoOptions& options) {
  port_ = port;
  clock_ = clock;
  options_ = options;
  if (options_.min_cluster == 0) options_.min_cluster = 1;
  parser_.reset();
  state_ = HokuyoState::kIdle;
  has_scan_ = false;
  have_ts_ = false;
  have_offset_ = false;
  failure_[0] = '\0';
}

bool HokuyoLaser::send_request(HokuyoState s) {
  char cmd[40];
  int n = 0;
  switch (s) {
    case HokuyoState::kScip2:
      // A SCIP 1.1 unit (early URG-04LX) switches on "SCIP2.0"; a SCIP 2.0 one answers and stays.
      n = std::snprintf(cmd, sizeof(cmd), "SCIP2.0\nQT\n");
      s = HokuyoState::kQuit;
      break;
    case HokuyoState::kQuit: n = std::snprintf(cmd, sizeof(cmd), "QT\n"); break;
    case HokuyoState::kVersion: n = std::snprintf(cmd, sizeof(cmd), "VV\n"); break;
    case HokuyoState::kParameters: n = std::snprintf(cmd, sizeof(cmd), "PP\n"); break;
    case HokuyoState::kStatus: n = std::snprintf(cmd, sizeof(cmd), "II\n"); break;
    case HokuyoState::kLaserOn: n = std::snprintf(cmd, sizeof(cmd), "BM\n"); break;
    case HokuyoState::kRequestScans:
      // Continuous acquisition (Sec. 8.1): scan interval 0, number of scans 00 = until QT.
      n = std::snprintf(cmd, sizeof(cmd), "%s%04u%04u%02u000\n", options_.intensity ? "ME" : "MD", first_, last_,
                        cluster_);
      break;
    case HokuyoState::kIdle:
    case HokuyoState::kStreaming: return true;
  }
  state_ = s;
  sent_ns_ = now_ns();
  if (!port_ || n <= 0) return false;
  return port_->write(reinterpret_cast<const std::uint8_t*>(cmd), static_cast<std::size_t>(n)) == n;
}

bool HokuyoLaser::start() {
  if (!port_) return false;
  return send_request(HokuyoState::kScip2);
}

bool HokuyoLaser::restart() {
  parser_.reset();
  has_scan_ = false;
  have_ts_ = false;
  have_offset_ = false;
  ++stats_.restarts;
  return start();
}

std::uint32_t HokuyoLaser::fault_bits() const {
  if (port_ != nullptr && !port_->connected()) return static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected);
  return 0;
}

SerialLaserCounters HokuyoLaser::counters() const {
  SerialLaserCounters c;
  c.scans = stats_.scans;
  c.checksum_errors = parser_.stats().checksum_errors;
  c.bad_measurements = stats_.bad_measurements;
  c.dropped = parser_.stats().malformed + parser_.stats().truncated + stats_.device_errors;
  c.device_restarts = stats_.device_restarts;
  return c;
}

void HokuyoLaser::describe_handshake(char* out, std::size_t cap) const {
  const ScipParserStats& p = parser_.stats();
  std::snprintf(out, cap, "no complete SCIP 2.0 handshake (waiting for the %s answer; %u answers, %u sum errors, "
                "%u malformed; last line received: '%s')%s%s",
                hokuyo_state_name(state_), p.responses, p.checksum_errors, p.malformed,
                parser_.last_line()[0] ? parser_.last_line() : "(nothing)", failure_[0] ? "; " : "", failure_);
}

void HokuyoLaser::on_handshake_answer(const ScipResponse& r) {
  const char* want = state_ == HokuyoState::kQuit         ? "QT"
                     : state_ == HokuyoState::kVersion    ? "VV"
                     : state_ == HokuyoState::kParameters ? "PP"
                     : state_ == HokuyoState::kStatus     ? "II"
                     : state_ == HokuyoState::kLaserOn    ? "BM"
                                                          : (options_.intensity ? "ME" : "MD");
  if (std::strcmp(r.command, want) != 0) {
    ++stats_.stale_answers;
    return;
  }
  const bool ok = (r.status[0] == '0' && r.status[1] == '0') ||
                  (state_ == HokuyoState::kLaserOn && r.status[0] == '0' && r.status[1] == '2');
  if (state_ == HokuyoState::kRequestScans && r.status[0] == '9' && r.status[1] == '9') {
    // Its "00" was lost on the line; the scans themselves confirm the request.
    state_ = HokuyoState::kStreaming;
    last_scan_ns_ = now_ns();
    on_scan_answer(r);
    return;
  }
  if (!ok) {
    ++stats_.device_errors;
    std::snprintf(failure_, sizeof(failure_), "%s answered status '%s'", r.command, r.status);
    return;  // sent again after answer_timeout_ms
  }
  switch (state_) {
    case HokuyoState::kQuit: send_request(HokuyoState::kVersion); return;
    case HokuyoState::kVersion:
      if (!scip_info_value(r, "PROD", product_, sizeof(product_))) product_[0] = '\0';
      if (!scip_info_value(r, "FIRM", firmware_, sizeof(firmware_))) firmware_[0] = '\0';
      send_request(HokuyoState::kParameters);
      return;
    case HokuyoState::kParameters: {
      const fw::Status s = decode_scip_parameters(r, &params_);
      if (!s) {
        std::snprintf(failure_, sizeof(failure_), "%.150s", s.message());
        return;
      }
      first_ = params_.amin;
      last_ = params_.amax;
      const std::uint32_t steps = last_ - first_ + 1;
      cluster_ = (steps + hal::LaserScan::kMaxBeams - 1) / hal::LaserScan::kMaxBeams;
      if (cluster_ < options_.min_cluster) cluster_ = options_.min_cluster;
      if (cluster_ > 99) cluster_ = 99;
      send_request(HokuyoState::kStatus);
      return;
    }
    case HokuyoState::kStatus: send_request(HokuyoState::kLaserOn); return;
    case HokuyoState::kLaserOn: send_request(HokuyoState::kRequestScans); return;
    case HokuyoState::kRequestScans:
      state_ = HokuyoState::kStreaming;
      failure_[0] = '\0';
      last_scan_ns_ = now_ns();
      return;
    default: return;
  }
}

std::uint64_t HokuyoLaser::stamp(std::uint32_t ts) {
  if (have_ts_ && ts < last_ts_) {
    if (last_ts_ - ts > 0x800000u) {
      epoch_ms_ += 0x1000000ull;  // the 24-bit counter wrapped (every 4.66 h)
      ++stats_.timestamp_wraps;
    } else {
      ++stats_.timestamp_resets;  // the sensor restarted its clock: anchor again
      have_offset_ = false;
    }
  }
  have_ts_ = true;
  last_ts_ = ts;
  sensor_ms_ = epoch_ms_ + ts;
  const std::int64_t sensor_ns = static_cast<std::int64_t>(sensor_ms_ * kHokuyoNsPerMs);
  if (!clock_) return static_cast<std::uint64_t>(sensor_ns);
  const std::int64_t cand = static_cast<std::int64_t>(clock_->now_ns()) - sensor_ns;
  if (!have_offset_ || cand < offset_ns_ + 1000) {
    offset_ns_ = cand;
  } else {
    offset_ns_ += 1000;  // creep: follows a sensor clock slower than the host's
  }
  have_offset_ = true;
  return static_cast<std::uint64_t>(sensor_ns + offset_ns_);
}

void HokuyoLaser::convert(const ScipScan& s) {
  hal::LaserScan& o = scan_;
  const double step = kTwoPi / static_cast<double>(params_.ares);
  const double centre = static_cast<double>(first_) + 0.5 * static_cast<double>(cluster_ - 1);
  o.timestamp_ns = stamp(s.timestamp_ms);
  o.scan_id = next_id_++;
  o.beam_count = s.count;
  o.angle_min = static_cast<float>((centre - static_cast<double>(params_.afrt)) * step);
  o.angle_increment = static_cast<float>(step * static_cast<double>(cluster_));
  o.range_min = static_cast<float>(params_.dmin_mm) * 0.001f;
  o.range_max = static_cast<float>(params_.dmax_mm) * 0.001f;
  for (std::uint32_t i = 0; i < s.count; ++i) {
    const std::uint32_t v = s.ranges_mm[i];
    o.ranges[i] = (v < params_.dmin_mm || v > params_.dmax_mm) ? o.range_max : static_cast<float>(v) * 0.001f;
  }
}

void HokuyoLaser::on_scan_answer(const ScipResponse& r) {
  const char* ours = options_.intensity ? "ME" : "MD";
  if (std::strcmp(r.command, ours) != 0) {
    ++stats_.stale_answers;
    return;
  }
  if (r.status[0] == '0' && r.status[1] == '0') return;  // a repeated acknowledgement
  if (r.status[0] != '9' || r.status[1] != '9') {
    ++stats_.device_errors;  // e.g. 50..97 hardware trouble, 98 resumed after an error
    return;
  }
  const fw::Status st = decode_scip_scan(r, &decoded_);
  const std::uint32_t c = decoded_.echo.cluster == 0 ? 1 : decoded_.echo.cluster;
  if (!st || decoded_.echo.start != first_ || decoded_.echo.end != last_ || c != cluster_ ||
      decoded_.count > hal::LaserScan::kMaxBeams) {
    ++stats_.bad_measurements;
    return;
  }
  if (has_scan_) ++stats_.overwritten;
  convert(decoded_);
  has_scan_ = true;
  ++stats_.scans;
  last_scan_ns_ = now_ns();
}

void HokuyoLaser::on_answer(const ScipResponse& r) {
  if (state_ == HokuyoState::kStreaming) {
    on_scan_answer(r);
  } else if (state_ != HokuyoState::kIdle) {
    on_handshake_answer(r);
  }
}

void HokuyoLaser::tick() {
  if (!clock_ || !port_ || !port_->connected() || state_ == HokuyoState::kIdle) return;
  const std::uint64_t now = clock_->now_ns();
  if (state_ == HokuyoState::kStreaming) {
    if (options_.silence_restart_ms == 0 || now - last_scan_ns_ < options_.silence_restart_ms * kHokuyoNsPerMs) return;
    ++stats_.device_restarts;  // reset or power dip: the device forgot our request
    parser_.reset();
    have_offset_ = false;
    send_request(HokuyoState::kScip2);
    return;
  }
  if (now - sent_ns_ < options_.answer_timeout_ms * kHokuyoNsPerMs) return;
  ++stats_.retries;
  send_request(state_);
}

bool HokuyoLaser::poll(hal::LaserScan* out) {
  if (!port_) return false;
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
      while (parser_.next(&answer_)) on_answer(answer_);
    }
  }
  tick();
  if (!has_scan_) return false;
  *out = scan_;
  has_scan_ = false;
  return true;
}

}  // namespace hal_serial
