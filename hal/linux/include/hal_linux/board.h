// Board: the Linux backend set behind hal::Hal (ArduPilot style: the backend is chosen when the
// binary is linked and configured at start-up; firmware code never includes a backend).
// create_board() builds the HAL from backend specs:
//   laser:    "socketcan:IFACE"  scans as the mmlfw CAN message set (hal/can)
//             "serial:DEVICE[@BAUD]"  SICK LMS2xx telegrams on a serial port (hal/serial)
//   odometry: "socketcan:IFACE" | "none" (zero odometry at the scan rate: a parked robot)
//   output:   "socketcan:IFACE" (pose + health frames) | "log" (text on stderr)
// One SocketCanBus per distinct interface; everything is a member (no heap).
#pragma once

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

// Parses "kind:arg" (kind socketcan|serial) into the parts; errors name the spec.
fw::Status parse_backend_spec(const char* what, const char* spec, char* kind, std::size_t kind_len, char* arg,
                              std::size_t arg_len);

class Board {
 public:
  Board() : zero_odom_(this), log_sink_pose_(this) {}
  Board(const Board&) = delete;
  Board& operator=(const Board&) = delete;

  fw::Status create(const BoardSpec& spec);
  hal::Hal& hal() { return hal_; }
  // Sleeps until input may be pending on any bus/port or timeout_ms passes (poll(2)).
  void wait_for_input(int timeout_ms);
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
  };

  hal::Hal hal_;
  LinuxClock clock_;
  StderrLogSink log_;
  hal_socketcan::SocketCanBus bus_;
  hal_can::CanNode node_;
  bool node_used_ = false;
  bool can_fd_ = false;
  hal_serial::TermiosPort port_;
  hal_serial::SickLaser sick_;
  bool sick_used_ = false;
  ZeroOdometry zero_odom_;
  LogPoseSink log_sink_pose_;
  char description_[200] = {0};
};

}  // namespace hal_linux
