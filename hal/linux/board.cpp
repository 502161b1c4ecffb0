#include "hal_linux/board.h"

#include <poll.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace hal_linux {

using fw::Errc;
using fw::Status;

Status parse_backend_spec(const char* what, const char* spec, char* kind, std::size_t kind_len, char* arg,
                          std::size_t arg_len) {
  if (!spec || !*spec) return Status::error(Errc::kInvalidArgument, "%s: empty backend spec", what);
  const char* colon = std::strchr(spec, ':');
  if (!colon) {
    if (std::strlen(spec) >= kind_len) return Status::error(Errc::kInvalidArgument, "%s: '%s' unknown", what, spec);
    std::strcpy(kind, spec);
    arg[0] = '\0';
    return Status::ok();
  }
  const std::size_t kl = static_cast<std::size_t>(colon - spec);
  if (kl == 0 || kl >= kind_len || !colon[1]) {
    return Status::error(Errc::kInvalidArgument, "%s: '%s' is not KIND:ARG (socketcan:IFACE, sick|hokuyo|rplidar:DEVICE[@BAUD])",
                         what, spec);
  }
  if (std::strlen(colon + 1) >= arg_len) {
    return Status::error(Errc::kInvalidArgument, "%s: '%s': argument too long (%zu characters, at most %zu)", what,
                         spec, std::strlen(colon + 1), arg_len - 1);
  }
  std::memcpy(kind, spec, kl);
  kind[kl] = '\0';
  std::strcpy(arg, colon + 1);
  return Status::ok();
}

bool Board::ZeroOdometry::poll(hal::Odometry* out) {
  // A parked robot: zero pose samples every 10 ms of HAL time so scans always pair.
  const std::uint64_t now = board_->clock_.now_ns();
  if (last_ns_ != 0 && now - last_ns_ < 10'000'000) return false;
  last_ns_ = now;
  *out = hal::Odometry{};
  out->timestamp_ns = now;
  return true;
}

bool Board::MountedLaser::poll(hal::LaserScan* out) {
  if (!inner_->poll(out)) return false;
  const std::uint32_t n = out->beam_count;
  if (upside_down_ && n > 0) {
    // Mirrored: beam i at angle a is seen at -a; reversed, the grid stays regular and ascending.
    for (std::uint32_t i = 0, j = n - 1; i < j; ++i, --j) {
      const float t = out->ranges[i];
      out->ranges[i] = out->ranges[j];
      out->ranges[j] = t;
    }
    out->angle_min = -(out->angle_min + static_cast<float>(n - 1) * out->angle_increment);
  }
  float a = out->angle_min + yaw_rad_;
  const float pi = 3.14159265f;
  while (a < -pi) a += 2.0f * pi;
  while (a >= pi) a -= 2.0f * pi;
  out->angle_min = a;
  return true;
}

void Board::LogPoseSink::publish(const hal::PoseEstimate& e) {
  board_->log_.log(hal::LogLevel::kInfo, "pose scan=%u x=%.3f y=%.3f th=%.4f status=%s", e.scan_id,
                   static_cast<double>(e.x), static_cast<double>(e.y), static_cast<double>(e.theta),
                   hal::status_name(e.status));
}

void Board::LogPoseSink::publish_health(const hal::Health& h) {
  // Every 50th frame, and at once whenever the fault bits change.
  const bool changed = h.fault_bits != last_fault_bits_;
  last_fault_bits_ = h.fault_bits;
  if (++health_count_ % 50 != 1 && !changed) return;
  char names[64] = "";
  const hal::HealthFault named[] = {hal::HealthFault::kLaserTimeout, hal::HealthFault::kLaserDisconnected};
  for (hal::HealthFault f : named) {
    if ((h.fault_bits & static_cast<std::uint32_t>(f)) == 0) continue;
    const std::size_t n = std::strlen(names);
    std::snprintf(names + n, sizeof(names) - n, " %s", hal::health_fault_name(f));
  }
  board_->log_.log(h.fault_bits ? hal::LogLevel::kWarning : hal::LogLevel::kInfo,
                   "health scans=%u dropped=%u invalid=%u timeouts=%u deadline_misses=%u faults=0x%x%s",
                   h.scans_processed, h.dropped_scans, h.invalid_scans, h.timeouts, h.deadline_misses, h.fault_bits,
                   names);
}

std::uint32_t default_serial_baud(const char* kind) {
  if (!std::strcmp(kind, "serial") || !std::strcmp(kind, "sick")) return 38400;
  if (!std::strcmp(kind, "hokuyo") || !std::strcmp(kind, "rplidar")) return 115200;
  return 0;
}

namespace {

// A decimal number in lo..hi (digits only).
bool small_number(const char* s, std::uint32_t lo, std::uint32_t hi, std::uint32_t* out) {
  std::uint32_t v = 0;
  if (!*s || std::strlen(s) > 7) return false;
  for (const char* c = s; *c; ++c) {
    if (*c < '0' || *c > '9') return false;
    v = v * 10 + static_cast<std::uint32_t>(*c - '0');
  }
  *out = v;
  return v >= lo && v <= hi;
}

// One ",OPTION" of a serial laser spec; false if the kind does not take it.
bool laser_option(const char* kind, const char* opt, SerialLaserSpec* out) {
  const bool hokuyo = !std::strcmp(kind, "hokuyo"), rplidar = !std::strcmp(kind, "rplidar");
  std::uint32_t v = 0;
  if (hokuyo && !std::strcmp(opt, "intensity")) {
    out->intensity = true;
  } else if (rplidar && (!std::strcmp(opt, "express") || !std::strcmp(opt, "force"))) {
    std::snprintf(out->mode, sizeof(out->mode), "%s", opt);
  } else if (rplidar && !std::strncmp(opt, "pwm=", 4) && small_number(opt + 4, 1, 1023, &v)) {
    out->motor_pwm = static_cast<std::uint16_t>(v);
  } else if (rplidar && !std::strncmp(opt, "beams=", 6) && small_number(opt + 6, 1, hal::LaserScan::kMaxBeams, &v)) {
    out->beams = v;
  } else {
    return false;
  }
  return true;
}

}  // namespace

Status parse_serial_laser_spec(const char* kind, const char* arg, SerialLaserSpec* out) {
  *out = SerialLaserSpec{};
  if (std::strlen(arg) >= sizeof(out->device)) {
    return Status::error(Errc::kInvalidArgument, "laser: %s:%s: argument too long", kind, arg);
  }
  std::strcpy(out->device, arg);
  if (char* comma = std::strchr(out->device, ',')) {
    *comma = '\0';
    for (char* opt = comma + 1; opt != nullptr;) {
      char* next = std::strchr(opt, ',');
      if (next != nullptr) *next++ = '\0';
      if (!laser_option(kind, opt, out)) {
        return Status::error(Errc::kInvalidArgument,
                             "laser: %s:%s: option '%s' unknown (hokuyo: intensity; rplidar: express, force, pwm=1..1023, "
                             "beams=1..1081)", kind, arg, opt);
      }
      opt = next;
    }
  }
  out->baud = default_serial_baud(kind);
  if (char* at = std::strchr(out->device, '@')) {
    *at = '\0';
    // Digits only and no wrap-around: "@4295005696" (2^32 + 38400) used to run at 38400 Bd.
    const char* b = at + 1;
    std::uint64_t v = 0;
    bool ok = *b != '\0';
    for (const char* c = b; ok && *c; ++c) {
      ok = *c >= '0' && *c <= '9';
      v = v * 10 + static_cast<std::uint64_t>(*c - '0');
      if (v > 0xFFFFFFFFull) ok = false;
    }
    if (!ok) return Status::error(Errc::kInvalidArgument, "laser: baud '%s' is not a rate in Bd", b);
    out->baud = static_cast<std::uint32_t>(v);
  }
  if (!out->device[0]) return Status::error(Errc::kInvalidArgument, "laser: %s:%s: no device", kind, arg);
  return Status::ok();
}

// The RPLIDAR A1's USB adapter: DTR cleared runs the motor, set stops it (the SDK's
// startMotor/stopMotor). A pty has no modem lines: refused, counted by the driver.
bool Board::rplidar_motor(void* board, bool on) {
  return static_cast<Board*>(board)->port_.set_dtr(!on).is_ok();
}

// Polls the driver until its handshake is done or handshake_ms passed (requests are resent
// inside); the error names the port and what the device answered.
Status Board::await_handshake(const char* kind, std::uint32_t handshake_ms) {
  const std::uint64_t end = clock_.now_ns() + static_cast<std::uint64_t>(handshake_ms) * 1000000ull;
  while (!serial_laser_->ready() && clock_.now_ns() < end && port_.is_open()) {
    port_.wait_readable(20);
    serial_laser_->poll(&handshake_scan_);
  }
  if (serial_laser_->ready()) return Status::ok();
  char what[320];
  serial_laser_->describe_handshake(what, sizeof(what));
  return Status::error(Errc::kTimeout, "laser: %s on '%s' at %u Bd: no answer as a %s within %u ms: %s", kind,
                       serial_device_, serial_baud_, serial_laser_->protocol_name(), handshake_ms, what);
}

Status Board::open_serial_laser(const char* kind, const char* arg, std::uint32_t handshake_ms) {
  SerialLaserSpec ls;
  FW_RETURN_IF_ERROR(parse_serial_laser_spec(kind, arg, &ls));
  FW_RETURN_IF_ERROR(port_.open(ls.device, ls.baud));
  std::snprintf(serial_device_, sizeof(serial_device_), "%s", ls.device);
  serial_baud_ = ls.baud;
  serial_down_ = false;
  // The drivers read and write through the recorder: the black box (attach_serial_black_box) sees
  // the bytes exactly as the driver does; without one it only passes them through.
  recording_port_.init(&port_, &clock_, nullptr);
  if (!std::strcmp(kind, "hokuyo")) {
    hal_serial::HokuyoOptions o;
    o.intensity = ls.intensity;
    hokuyo_.init(&recording_port_, &clock_, o);
    serial_laser_ = &hokuyo_;
  } else if (!std::strcmp(kind, "rplidar")) {
    hal_serial::RplidarOptions o;
    if (!std::strcmp(ls.mode, "express")) o.mode = hal_serial::RplidarScanMode::kExpress;
    if (!std::strcmp(ls.mode, "force")) o.mode = hal_serial::RplidarScanMode::kForceScan;
    o.motor_pwm = ls.motor_pwm;
    if (ls.beams > 0) o.revolution.beams = ls.beams;
    rplidar_.init(&recording_port_, &clock_, o);
    rplidar_.set_motor_control(&Board::rplidar_motor, this);
    serial_laser_ = &rplidar_;
  } else {
    sick_.init(&recording_port_, &clock_, hal_serial::SickLaserOptions{});
    serial_laser_ = &sick_;
  }
  if (!serial_laser_->start()) {
    return Status::error(Errc::kIoError, "laser: %s on '%s': request write failed", kind, ls.device);
  }
  return await_handshake(kind, handshake_ms);
}

Status Board::create(const BoardSpec& spec) {
  log_ = StderrLogSink(spec.log_level);
  hal_ = hal::Hal{};
  hal_.clock = &clock_;
  hal_.log = &log_;
  char lkind[16], larg[kMaxBackendArg];
  FW_RETURN_IF_ERROR(parse_backend_spec("laser", spec.laser, lkind, sizeof(lkind), larg, sizeof(larg)));
  if (std::strcmp(lkind, "can") == 0) std::strcpy(lkind, "socketcan");  // laser = can:IFACE
  const bool laser_can = std::strcmp(lkind, "socketcan") == 0;
  if (!laser_can && default_serial_baud(lkind) == 0) {
    return Status::error(Errc::kInvalidArgument,
                         "laser: backend '%s' unknown (can:IFACE, sick:DEVICE, hokuyo:DEVICE, rplidar:DEVICE)", lkind);
  }
  char can_spec[kMaxBackendArg + 16];
  std::snprintf(can_spec, sizeof(can_spec), "socketcan:%s", larg);
  const char* odom_spec = spec.odometry ? spec.odometry : (laser_can ? can_spec : "none");
  const char* out_spec = spec.output ? spec.output : (laser_can ? can_spec : "log");
  char okind[16], oarg[kMaxBackendArg], pkind[16], parg[kMaxBackendArg];
  FW_RETURN_IF_ERROR(parse_backend_spec("odometry", odom_spec, okind, sizeof(okind), oarg, sizeof(oarg)));
  FW_RETURN_IF_ERROR(parse_backend_spec("output", out_spec, pkind, sizeof(pkind), parg, sizeof(parg)));

  // All CAN roles must share one interface (one socket, one CanNode).
  char can_iface_buf[kMaxBackendArg] = {0};
  auto want_can = [&can_iface_buf](const char* role, const char* kind, const char* arg) -> Status {
    if (std::strcmp(kind, "socketcan") != 0) return Status::ok();
    if (can_iface_buf[0] && std::strcmp(can_iface_buf, arg) != 0) {
      return Status::error(Errc::kUnsupported, "%s: socketcan:%s differs from socketcan:%s (one CAN interface per board)",
                           role, arg, can_iface_buf);
    }
    std::snprintf(can_iface_buf, sizeof(can_iface_buf), "%s", arg);
    return Status::ok();
  };
  FW_RETURN_IF_ERROR(want_can("laser", lkind, larg));
  FW_RETURN_IF_ERROR(want_can("odometry", okind, oarg));
  FW_RETURN_IF_ERROR(want_can("output", pkind, parg));
  const char* can_iface = can_iface_buf[0] ? can_iface_buf : nullptr;
  if (std::strcmp(okind, "socketcan") != 0 && std::strcmp(okind, "none") != 0) {
    return Status::error(Errc::kInvalidArgument, "odometry: backend '%s' unknown (socketcan:IFACE or none)", okind);
  }
  if (std::strcmp(pkind, "socketcan") != 0 && std::strcmp(pkind, "log") != 0) {
    return Status::error(Errc::kInvalidArgument, "output: backend '%s' unknown (socketcan:IFACE or log)", pkind);
  }

  if (can_iface) {
    hal_socketcan::SocketCanOptions o;
    o.want_fd = spec.can_fd != 0;
    o.require_fd = spec.can_fd == 1;
    // Only our message set: IDs 0x100..0x13F and their FD variants 0x500..0x53F, and the operator
    // commands 0x140..0x14F / 0x540..0x54F (issue 60).
    o.filters[0] = {0x100, 0x7C0, false};
    o.filters[1] = {0x500, 0x7C0, false};
    o.filters[2] = {0x140, 0x7F0, false};
    o.filters[3] = {0x540, 0x7F0, false};
    o.num_filters = 4;
    FW_RETURN_IF_ERROR(bus_.open(can_iface, o));
    can_fd_ = bus_.fd_enabled();
    node_.init(&bus_, &clock_, can_fd_);
    node_used_ = true;
  }
  if (laser_can) {
    mounted_laser_.set(&node_.laser(), spec.laser_yaw_rad, spec.laser_upside_down);
  } else {
    FW_RETURN_IF_ERROR(open_serial_laser(lkind, larg, spec.laser_handshake_ms));
    mounted_laser_.set(serial_laser_, spec.laser_yaw_rad, spec.laser_upside_down);
  }
  hal_.laser = &mounted_laser_;
  hal_.odometry = std::strcmp(okind, "socketcan") == 0 ? &node_.odometry() : static_cast<hal::OdometrySource*>(&zero_odom_);
  hal_.pose_sink = std::strcmp(pkind, "socketcan") == 0 ? &node_.pose_sink() : static_cast<hal::PoseSink*>(&log_sink_pose_);
  // Operator commands arrive where the poses go out (the robot's bus).
  hal_.commands = std::strcmp(pkind, "socketcan") == 0 ? &node_.commands() : nullptr;
  char device[96] = "";
  if (serial_laser_ == &hokuyo_) {
    const hal_serial::ScipParameters& pp = hokuyo_.parameters();
    std::snprintf(device, sizeof(device), " (%.40s, steps %u..%u of %u, %u..%u mm)", hokuyo_.product(), pp.amin, pp.amax,
                  pp.ares, pp.dmin_mm, pp.dmax_mm);
  } else if (serial_laser_ == &rplidar_) {
    const hal_serial::RplidarInfo& i = rplidar_.info();
    std::snprintf(device, sizeof(device), " (RPLIDAR model 0x%02X, firmware %u.%02u, hardware %u, health %u)", i.model,
                  i.firmware_major, i.firmware_minor, i.hardware, rplidar_.health().status);
  }
  std::snprintf(description_, sizeof(description_), "laser=%s%s odometry=%s output=%s%s", spec.laser, device, odom_spec,
                out_spec, can_iface ? (can_fd_ ? " (CAN FD)" : " (classic CAN)") : "");
  return Status::ok();
}

void Board::service_serial_link() {
  if (serial_laser_ == nullptr) return;
  const std::uint64_t now = clock_.now_ns();
  if (!serial_down_) {
    if (port_.is_open()) return;
    // Lost since the last call (read error or hang-up): say so once and schedule the reopen.
    serial_down_ = true;
    serial_down_ns_ = now;
    serial_backoff_ns_ = static_cast<std::uint64_t>(kSerialRetryMinMs) * 1000000ull;
    serial_retry_ns_ = now + serial_backoff_ns_;
    serial_failed_attempts_ = 0;
    const int e = port_.last_error();
    log_.log(hal::LogLevel::kWarning, "laser: serial '%s' lost (%s): fault %s, reopening every %d..%d ms",
             serial_device_, e != 0 ? std::strerror(e) : "hang-up",
             hal::health_fault_name(hal::HealthFault::kLaserDisconnected), kSerialRetryMinMs, kSerialRetryMaxMs);
    return;
  }
  if (now < serial_retry_ns_) return;
  const Status s = port_.open(serial_device_, serial_baud_);
  if (s.is_ok() && serial_laser_->restart()) {
    serial_down_ = false;
    ++serial_reconnects_;
    log_.log(hal::LogLevel::kInfo, "laser: serial '%s' reopened after %.1f s (%u attempts); %s scans requested",
             serial_device_, static_cast<double>(now - serial_down_ns_) * 1e-9, serial_failed_attempts_ + 1,
             serial_laser_->protocol_name());
    return;
  }
  if (s.is_ok()) port_.hang_up(0);  // opened but the request could not be written: try again later
  if (++serial_failed_attempts_ == 1) {
    log_.log(hal::LogLevel::kWarning, "laser: reopening serial '%s' failed: %s (retrying)", serial_device_,
             s.is_ok() ? "request write failed" : s.message());
  }
  serial_backoff_ns_ *= 2;
  const std::uint64_t max_ns = static_cast<std::uint64_t>(kSerialRetryMaxMs) * 1000000ull;
  if (serial_backoff_ns_ > max_ns) serial_backoff_ns_ = max_ns;
  serial_retry_ns_ = now + serial_backoff_ns_;
}

void Board::wait_for_input(int timeout_ms) {
  service_serial_link();
  pollfd p[2];
  int n = 0, serial = -1;
  if (bus_.is_open()) p[n++] = {bus_.native_handle(), POLLIN, 0};
  if (port_.is_open()) {
    serial = n;
    p[n++] = {port_.native_handle(), POLLIN, 0};
  }
  if (n == 0) {
    ::poll(nullptr, 0, timeout_ms);
    return;
  }
  if (::poll(p, static_cast<nfds_t>(n), timeout_ms) <= 0 || serial < 0) return;
  // A hung-up tty polls "ready" forever. With data still buffered (POLLIN) the reader drains it
  // first (a pty whose peer closed then fails the read with EIO and the port closes itself); a
  // hang-up still reported on the next wait means nothing more will come: drop the port here.
  const short r = p[serial].revents;
  if ((r & (POLLHUP | POLLERR | POLLNVAL)) == 0) {
    serial_hup_polls_ = 0;
    return;
  }
  if ((r & POLLIN) != 0 && ++serial_hup_polls_ < 2) return;
  serial_hup_polls_ = 0;
  port_.hang_up(0);
  service_serial_link();
}

}  // namespace hal_linux
