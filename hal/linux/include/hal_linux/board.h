// Board: the Linux backend set behind hal::Hal (ArduPilot style: the backend is chosen when the
// binary is linked and configured at start-up; firmware code never includes a backend).
// create_board() builds the HAL from backend specs:
//   laser:    "socketcan:IFACE"  scans as the mmlfw CAN message set (hal/can)
//             "serial:DEVICE[@BAUD]"  SICK LMS2xx telegrams on a serial port (hal/serial)
//   odometry: "socketcan:IFACE" | "none" (zero odometry at the scan rate: a parked robot)
//   output:   "socketcan:IFACE" (pose + health frames) | "log" (text on stderr)
// One SocketCanBus per distinct interface; everything is a member (no heap).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/hal.h"
#include "hal_can/can_node.h"
#include "hal_linux/linux_clock.h"
#include "hal_linux/stderr_log_sink.h"
#include "hal_serial/sick_laser.h"
#include "hal_serial/termios_port.h"
#include "hal_socketcan/socketcan_bus.h"

namespace hal_linux {

struct BoardSpec {
  const char* laser = nullptr;
  const char* odometry = nullptr;  // nullptr = same as laser when that is socketcan, else "none"
  const char* output = nullptr;    // nullptr = same as laser when that is socketcan, else "log"
  int can_fd = -1;                 // -1 auto (FD when the interface MTU allows), 0 classic, 1 require FD
  hal::LogLevel log_level = hal::LogLevel::kInfo;
};

// Longest "arg" of a backend spec + 1 (the config's laser/odometry/output values are < 128).
constexpr std::size_t kMaxBackendArg = 128;

// Parses "kind:arg" (kind socketcan|serial) into the parts; errors name the spec and say whether
// it is malformed or too long.
fw::Status parse_backend_spec(const char* what, const char* spec, char* kind, std::size_t kind_len, char* arg,
                              std::size_t arg_len);

class Board {
 public:
  Board() : zero_odom_(this), log_sink_pose_(this) {}
  Board(const Board&) = delete;
  Board& operator=(const Board&) = delete;

  fw::Status create(const BoardSpec& spec);
  hal::Hal& hal() { return hal_; }
  // Sleeps until input may be pending on any bus/port or timeout_ms passes (poll(2)). A serial
  // laser port that hung up (peer closed, device unplugged) is closed here and reopened with a
  // back-off (kSerialRetryMinMs doubling to kSerialRetryMaxMs): the loop never spins on a dead
  // descriptor, HEALTH shows laser-disconnected meanwhile, and the scans resume when it returns.
  void wait_for_input(int timeout_ms);
  static constexpr int kSerialRetryMinMs = 100;
  static constexpr int kSerialRetryMaxMs = 2000;
  // Times the serial laser port was reopened after it was lost.
  std::uint32_t serial_reconnects() const { return serial_reconnects_; }
  // Publishes a heartbeat even when no scans arrive (health frames keep flowing).
  void publish_heartbeat(const hal::Health& h) { if (hal_.pose_sink) hal_.pose_sink->publish_health(h); }

  bool can_fd() const { return can_fd_; }
  const hal_can::CanNode* can_node() const { return node_used_ ? &node_ : nullptr; }
  const hal_socketcan::SocketCanBus* can_bus() const { return bus_.is_open() ? &bus_ : nullptr; }
  const hal_serial::SickLaser* sick() const { return sick_used_ ? &sick_ : nullptr; }
  const char* describe() const { return description_; }

 private:
  class ZeroOdometry final : public hal::OdometrySource {
   public:
    explicit ZeroOdometry(Board* b) : board_(b) {}
    bool poll(hal::Odometry* out) override;
   private:
    Board* board_;
    std::uint64_t last_ns_ = 0;
  };
  class LogPoseSink final : public hal::PoseSink {
   public:
    explicit LogPoseSink(Board* b) : board_(b) {}
    void publish(const hal::PoseEstimate& e) override;
    void publish_health(const hal::Health& h) override;
   private:
    Board* board_;
    std::uint32_t health_count_ = 0;
    std::uint32_t last_fault_bits_ = 0;
  };

  hal::Hal hal_;
  LinuxClock clock_;
  StderrLogSink log_;
  hal_socketcan::SocketCanBus bus_;
  hal_can::CanNode node_;
  bool node_used_ = false;
  bool can_fd_ = false;
  void service_serial_link();
  hal_serial::TermiosPort port_;
  hal_serial::SickLaser sick_;
  bool sick_used_ = false;
  char serial_device_[kMaxBackendArg] = {0};
  std::uint32_t serial_baud_ = 0;
  bool serial_down_ = false;            // lost and not yet reopened
  std::uint64_t serial_down_ns_ = 0;    // when it was lost
  std::uint64_t serial_retry_ns_ = 0;   // next reopen attempt
  std::uint64_t serial_backoff_ns_ = 0;
  std::uint32_t serial_reconnects_ = 0;
  std::uint32_t serial_failed_attempts_ = 0;
  int serial_hup_polls_ = 0;            // consecutive waits that saw a hang-up with data pending
  ZeroOdometry zero_odom_;
  LogPoseSink log_sink_pose_;
  char description_[200] = {0};
};

}  // namespace hal_linux
