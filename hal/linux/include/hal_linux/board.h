// Board: the Linux backend set behind hal::Hal (ArduPilot style: the backend is chosen when the
// binary is linked and configured at start-up; firmware code never includes a backend).
// create_board() builds the HAL from backend specs:
//   laser:    "socketcan:IFACE" | "can:IFACE"  scans as the mmlfw CAN message set (hal/can)
//             "sick:DEVICE[@BAUD]" | "serial:DEVICE[@BAUD]"  SICK LMS2xx telegrams (hal/serial) [38400]
//             "hokuyo:DEVICE[@BAUD][,intensity]"  Hokuyo URG/UTM/UST, SCIP 2.0 [115200; USB-ACM ignores it]
//             "rplidar:DEVICE[@BAUD][,express|,force][,pwm=N][,beams=N]"  Slamtec RPLIDAR (SCAN,
//                        EXPRESS_SCAN legacy, FORCE_SCAN) [115200: A1/A2; 256000: A3/S1; 1000000: S2]
//             Hokuyo and RPLIDAR answer a start-up handshake; a device that does not within
//             BoardSpec::laser_handshake_ms is an error naming the port and what it answered.
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
#include "hal_serial/hokuyo_laser.h"
#include "hal_serial/recording_serial_port.h"
#include "hal_serial/serial_black_box.h"
#include "hal_serial/rplidar_laser.h"
#include "hal_serial/serial_laser.h"
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
  std::uint32_t laser_handshake_ms = 3000;  // Hokuyo / RPLIDAR start-up answers (retried within it)
  // How the laser sits on the robot (config laser_mount): its zero direction turned laser_yaw_rad
  // (CCW) from the robot's front, upside down (mirrored). Every scan is turned into the robot's
  // orientation before the firmware sees it (exact on the regular grid: angle_min moves, an upside
  // down scan is reversed). A lever arm is not modelled here.
  float laser_yaw_rad = 0.0f;
  bool laser_upside_down = false;
};

// Longest "arg" of a backend spec + 1 (the config's laser/odometry/output values are < 128).
constexpr std::size_t kMaxBackendArg = 128;

// A serial laser spec "DEVICE[@BAUD][,OPTION]..." taken apart (board.cpp; the config checks it too).
// Options: hokuyo "intensity" (ME); rplidar "express" | "force" (the scan request), "pwm=N" (A2/A3:
// SET_MOTOR_PWM duty 1..1023, the SDK's default 660; the A1 runs on DTR), "beams=N" (grid slots over
// 360°, 1..1081; 360 by default, 720 or more for an A2/A3/S1 in express mode).
struct SerialLaserSpec {
  char device[kMaxBackendArg] = {0};
  std::uint32_t baud = 0;  // 0 = the protocol's default
  bool intensity = false;
  char mode[8] = {0};      // "", "express", "force"
  std::uint16_t motor_pwm = 0;
  std::uint32_t beams = 0;  // 0 = the driver's default
};
// Errors name the spec and the part that is wrong.
fw::Status parse_serial_laser_spec(const char* kind, const char* arg, SerialLaserSpec* out);
std::uint32_t default_serial_baud(const char* kind);

// Parses "kind:arg" (kind socketcan|can|serial|sick|hokuyo|rplidar) into the parts; errors name the spec and say whether
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
  // The black box records the CAN node's traffic (false: no CAN node on this board).
  bool attach_black_box(hal_can::BlackBox* box) {
    if (!node_used_) return false;
    node_.attach_black_box(box);
    return true;
  }
  // The black box records the serial laser's bytes (false: no serial laser on this board). The
  // start-up handshake is over by then; requests after a reopen or a device restart are recorded.
  bool attach_serial_black_box(hal_serial::SerialBlackBox* box) {
    if (serial_laser_ == nullptr) return false;
    recording_port_.set_black_box(box);
    return true;
  }
  const hal_socketcan::SocketCanBus* can_bus() const { return bus_.is_open() ? &bus_ : nullptr; }
  const hal_serial::SickLaser* sick() const { return serial_laser_ == &sick_ ? &sick_ : nullptr; }
  const hal_serial::HokuyoLaser* hokuyo() const { return serial_laser_ == &hokuyo_ ? &hokuyo_ : nullptr; }
  const hal_serial::RplidarLaser* rplidar() const { return serial_laser_ == &rplidar_ ? &rplidar_ : nullptr; }
  // The serial laser in use (SICK, Hokuyo or RPLIDAR), nullptr for a CAN laser.
  const hal_serial::SerialLaser* serial_laser() const { return serial_laser_; }
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
  // The laser source as the firmware sees it: the configured mount applied to every scan.
  class MountedLaser final : public hal::LaserScanSource {
   public:
    void set(hal::LaserScanSource* inner, float yaw_rad, bool upside_down) {
      inner_ = inner;
      yaw_rad_ = yaw_rad;
      upside_down_ = upside_down;
    }
    bool poll(hal::LaserScan* out) override;
    std::uint32_t fault_bits() const override { return inner_->fault_bits(); }
    std::uint32_t invalid_scans() const override { return inner_->invalid_scans(); }
    std::uint32_t skipped_scans() const override { return inner_->skipped_scans(); }
   private:
    hal::LaserScanSource* inner_ = nullptr;
    float yaw_rad_ = 0.0f;
    bool upside_down_ = false;
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
  fw::Status open_serial_laser(const char* kind, const char* arg, std::uint32_t handshake_ms);
  fw::Status await_handshake(const char* kind, std::uint32_t handshake_ms);
  static bool rplidar_motor(void* board, bool on);
  hal_serial::TermiosPort port_;
  hal_serial::RecordingSerialPort recording_port_;  // what the serial drivers read and write through
  hal_serial::SickLaser sick_;
  hal_serial::HokuyoLaser hokuyo_;
  hal_serial::RplidarLaser rplidar_;
  hal_serial::SerialLaser* serial_laser_ = nullptr;
  hal::LaserScan handshake_scan_;  // a scan polled while the handshake ends is dropped here
  MountedLaser mounted_laser_;
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
  char description_[512] = {0};
};

}  // namespace hal_linux
