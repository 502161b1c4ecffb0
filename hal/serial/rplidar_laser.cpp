#include "hal_serial/rplidar_laser.h"

#include <cstdio>
#include <cstring>

namespace hal_serial {

namespace {
constexpr std::uint64_t kRplidarNsPerMs = 1000000ull;
}  // namespace

const char* rplidar_state_name(RplidarState s) {
  switch (s) {
    case RplidarState::kIdle: return "idle";
    case RplidarState::kStopping: return "STOP";
    case RplidarState::kHealth: return "GET_HEALTH";
    case RplidarState::kInfo: return "GET_INFO";
    case RplidarState::kResetting: return "RESET";
    case RplidarState::kRequestScan: return "SCAN";
    case RplidarState::kStreaming: return "streaming";
  }
  return "?";
}

void RplidarLaser::init(hal::SerialPort* port, const hal::Clock* clock, const RplidarOptions& options) {
  port_ = port;
  clock_ = clock;
  options_ = options;
  revolution_.init(options.revolution);
  parser_.reset();
  state_ = RplidarState::kIdle;
  has_scan_ = false;
  failure_[0] = '\0';
}

bool RplidarLaser::send(std::uint8_t cmd, const std::uint8_t* payload, std::size_t n) {
  std::uint8_t req[16];
  const std::size_t len = encode_rplidar_request(cmd, payload, n, req, sizeof(req));
  sent_ns_ = now_ns();
  return port_ != nullptr && len > 0 && port_->write(req, len) == static_cast<long>(len);
}

bool RplidarLaser::start() {
  if (!port_) return false;
  if (motor_ != nullptr && !motor_(motor_context_, true)) ++stats_.motor_control_failed;
  revolution_.reset();
  // STOP ends a stream a previous run left going (it has no answer); what is still in flight is
  // skipped by the parser until GET_HEALTH's descriptor. GET_HEALTH follows stop_settle_ms later
  // (tick), at once without a clock.
  parser_.expect(kRplidarAnsHealth);
  state_ = RplidarState::kStopping;
  if (!send(kRplidarCmdStop)) return false;
  if (clock_ != nullptr && options_.stop_settle_ms > 0) return true;
  state_ = RplidarState::kHealth;
  return send(kRplidarCmdGetHealth);
}

bool RplidarLaser::restart() {
  ++stats_.restarts;
  has_scan_ = false;
  return start();
}

std::uint32_t RplidarLaser::fault_bits() const {
  if (port_ != nullptr && !port_->connected()) return static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected);
  return 0;
}

SerialLaserCounters RplidarLaser::counters() const {
  SerialLaserCounters c;
  c.scans = stats_.scans;
  c.checksum_errors = parser_.stats().checksum_errors + parser_.stats().check_errors;
  c.bad_measurements = revolution_.stats().overlong;
  c.dropped = revolution_.stats().partial;
  c.device_restarts = stats_.device_restarts;
  return c;
}

void RplidarLaser::describe_handshake(char* out, std::size_t cap) const {
  char hex[16 * 3 + 1] = {0};
  const std::uint32_t n = recent_n_ < sizeof(recent_) ? recent_n_ : static_cast<std::uint32_t>(sizeof(recent_));
  for (std::uint32_t i = 0; i < n; ++i) {
    // The ring holds the last bytes; print them oldest first.
    const std::uint32_t k = (recent_n_ - n + i) % sizeof(recent_);
    std::snprintf(hex + 3 * i, sizeof(hex) - 3 * i, "%02X ", recent_[k]);
  }
  if (n > 0) hex[3 * n - 1] = '\0';
  std::snprintf(out, cap, "no complete RPLIDAR handshake (waiting for the %s answer; %u bytes received%s%s%s)%s%s",
                rplidar_state_name(state_), recent_n_, n > 0 ? ", the last: " : "", hex, n > 0 ? "" : ", nothing",
                failure_[0] ? "; " : "", failure_);
}

void RplidarLaser::request_scan() {
  if (options_.motor_pwm > 0) {
    const std::uint8_t pwm[2] = {static_cast<std::uint8_t>(options_.motor_pwm),
                                 static_cast<std::uint8_t>(options_.motor_pwm >> 8)};
    send(kRplidarCmdSetMotorPwm, pwm, 2);
  }
  revolution_.reset();
  state_ = RplidarState::kRequestScan;
  if (options_.mode == RplidarScanMode::kExpress) {
    parser_.expect(kRplidarAnsCapsule);
    const std::uint8_t legacy[5] = {0, 0, 0, 0, 0};  // working mode 0: the legacy capsule format
    send(kRplidarCmdExpressScan, legacy, sizeof(legacy));
  } else {
    parser_.expect(kRplidarAnsSample);
    send(options_.mode == RplidarScanMode::kForceScan ? kRplidarCmdForceScan : kRplidarCmdScan);
  }
}

void RplidarLaser::on_event(const RplidarEvent& e) {
  switch (e.kind) {
    case RplidarEvent::Kind::kHealth:
      if (state_ != RplidarState::kHealth && state_ != RplidarState::kStopping) return;
      health_ = e.health;
      if (e.health.status == kRplidarHealthError) {
        ++stats_.health_errors;
        std::snprintf(failure_, sizeof(failure_), "GET_HEALTH: error, code 0x%04X (RESET sent)", e.health.error_code);
        parser_.reset();  // the reset banner is not an answer
        state_ = RplidarState::kResetting;
        send(kRplidarCmdReset);
        return;
      }
      if (e.health.status == kRplidarHealthWarning) ++stats_.health_warnings;
      if (e.health.status > kRplidarHealthError) {
        std::snprintf(failure_, sizeof(failure_), "GET_HEALTH: status %u unknown", e.health.status);
        return;  // asked again after answer_timeout_ms
      }
      parser_.expect(kRplidarAnsInfo);
      state_ = RplidarState::kInfo;
      send(kRplidarCmdGetInfo);
      return;
    case RplidarEvent::Kind::kInfo:
      if (state_ != RplidarState::kInfo) return;
      info_ = e.info;
      request_scan();
      return;
    case RplidarEvent::Kind::kStreamStarted:
      if (state_ != RplidarState::kRequestScan) return;
      state_ = RplidarState::kStreaming;
      failure_[0] = '\0';
      last_revolution_ns_ = now_ns();
      return;
    case RplidarEvent::Kind::kSample:
      if (state_ != RplidarState::kStreaming) return;
      if (revolution_.add(e.sample, now_ns(), &scan_)) {
        if (has_scan_) ++stats_.overwritten;
        has_scan_ = true;
        ++stats_.scans;
        last_revolution_ns_ = now_ns();
      }
      return;
  }
}

void RplidarLaser::tick() {
  if (!clock_ || !port_ || !port_->connected() || state_ == RplidarState::kIdle) return;
  const std::uint64_t now = clock_->now_ns();
  switch (state_) {
    case RplidarState::kResetting:
      if (now - sent_ns_ >= options_.reset_settle_ms * kRplidarNsPerMs) start();
      return;
    case RplidarState::kStopping:
      if (now - sent_ns_ < options_.stop_settle_ms * kRplidarNsPerMs) return;
      state_ = RplidarState::kHealth;
      send(kRplidarCmdGetHealth);
      return;
    case RplidarState::kStreaming:
      if (options_.silence_restart_ms == 0 || now - last_revolution_ns_ < options_.silence_restart_ms * kRplidarNsPerMs) return;
      ++stats_.device_restarts;  // motor stopped, device reset or the stream died
      start();
      return;
    default:
      if (now - sent_ns_ < options_.answer_timeout_ms * kRplidarNsPerMs) return;
      ++stats_.retries;
      start();
      return;
  }
}

void RplidarLaser::remember(const std::uint8_t* bytes, std::size_t n) {
  if (state_ == RplidarState::kStreaming) return;
  for (std::size_t i = 0; i < n; ++i) recent_[(recent_n_ + i) % sizeof(recent_)] = bytes[i];
  recent_n_ += static_cast<std::uint32_t>(n);
}

bool RplidarLaser::poll(hal::LaserScan* out) {
  if (!port_) return false;
  for (int i = 0; i < 8 && port_->connected(); ++i) {
    const long n = port_->read(rx_, sizeof(rx_));
    if (n < 0) {
      ++stats_.read_errors;
      break;
    }
    if (n == 0) break;
    remember(rx_, static_cast<std::size_t>(n));
    std::size_t off = 0;
    while (off < static_cast<std::size_t>(n)) {
      off += parser_.feed(rx_ + off, static_cast<std::size_t>(n) - off);
      while (parser_.next(&event_)) on_event(event_);
    }
  }
  tick();
  if (!has_scan_) return false;
  *out = scan_;
  has_scan_ = false;
  return true;
}

}  // namespace hal_serial
