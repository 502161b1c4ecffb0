// RplidarLaser: Slamtec RPLIDAR (A1/A2/A3, S1/S2) driver on any hal::SerialPort, after the
// protocol document and SDK (hal_serial/rplidar_protocol.h). Start-up, one request at a time:
//   motor on → STOP (stop_settle_ms: a unit still streaming may miss a request sent at once; the
//   protocol document asks for a pause after STOP, community drivers wait 10-100 ms) → GET_HEALTH (error: RESET, wait reset_settle_ms, again) → GET_INFO →
//   [SET_MOTOR_PWM for A2/A3] → SCAN | FORCE_SCAN | EXPRESS_SCAN (legacy capsules) → streaming;
// samples are assembled into revolutions and resampled onto a regular grid (rplidar_revolution.h).
// A request not answered within answer_timeout_ms, or a stream without a revolution for
// silence_restart_ms (motor stopped, device reset: it then prints its banner and waits), starts
// the handshake again from STOP.
// Motor: the A1's USB adapter drives the motor enable from DTR, which the SDK clears to start the
// motor and sets to stop it (rplidar_driver.cpp startMotor/stopMotor: clearDTR / setDTR); the
// A2/A3 take SET_MOTOR_PWM (the SDK's default duty 660). The board passes a motor function (DTR
// on a tty); a port without modem lines (a pty) refuses it, which is counted, not fatal.
#pragma once

#include <cstdint>

#include "hal/clock.h"
#include "hal/serial_port.h"
#include "hal_serial/rplidar_protocol.h"
#include "hal_serial/rplidar_revolution.h"
#include "hal_serial/serial_laser.h"

namespace hal_serial {

enum class RplidarScanMode : std::uint8_t { kScan, kForceScan, kExpress };

struct RplidarOptions {
  RplidarScanMode mode = RplidarScanMode::kScan;
  RplidarRevolutionOptions revolution;
  std::uint16_t motor_pwm = 0;              // A2/A3: SET_MOTOR_PWM duty 0..1023 (0: not sent; A1: DTR)
  std::uint32_t stop_settle_ms = 20;        // after STOP before the next request (see start())
  std::uint32_t answer_timeout_ms = 500;
  std::uint32_t reset_settle_ms = 1000;     // after RESET the device boots and prints a banner
  std::uint32_t silence_restart_ms = 2000;  // ≥ 10 revolutions of an A1 at 5.5 Hz
};

// Switches the motor (true = run); false if the line could not be set.
using RplidarMotorFn = bool (*)(void* context, bool on);

enum class RplidarState : std::uint8_t { kIdle, kStopping, kHealth, kInfo, kResetting, kRequestScan, kStreaming };
const char* rplidar_state_name(RplidarState s);

struct RplidarStats {
  std::uint32_t scans = 0;
  std::uint32_t overwritten = 0;
  std::uint32_t read_errors = 0;
  std::uint32_t health_warnings = 0;
  std::uint32_t health_errors = 0;       // GET_HEALTH said error: RESET sent
  std::uint32_t retries = 0;             // handshakes repeated after answer_timeout_ms
  std::uint32_t device_restarts = 0;     // handshakes repeated after silence_restart_ms
  std::uint32_t restarts = 0;            // restart() after the port was reopened
  std::uint32_t motor_control_failed = 0;
};

class RplidarLaser final : public SerialLaser {
 public:
  void init(hal::SerialPort* port, const hal::Clock* clock, const RplidarOptions& options);
  void set_motor_control(RplidarMotorFn fn, void* context) {
    motor_ = fn;
    motor_context_ = context;
  }
  bool start() override;
  bool restart() override;
  bool ready() const override { return state_ == RplidarState::kStreaming; }
  void describe_handshake(char* out, std::size_t cap) const override;
  SerialLaserCounters counters() const override;
  const char* protocol_name() const override { return "rplidar"; }

  bool poll(hal::LaserScan* out) override;
  std::uint32_t fault_bits() const override;
  std::uint32_t invalid_scans() const override { return revolution_.stats().overlong; }
  std::uint32_t skipped_scans() const override { return stats_.overwritten; }

  RplidarState state() const { return state_; }
  const RplidarInfo& info() const { return info_; }
  const RplidarHealth& health() const { return health_; }
  const RplidarParserStats& parser_stats() const { return parser_.stats(); }
  const RplidarRevolutionStats& revolution_stats() const { return revolution_.stats(); }
  const RplidarStats& stats() const { return stats_; }

 private:
  bool send(std::uint8_t cmd, const std::uint8_t* payload = nullptr, std::size_t n = 0);
  void on_event(const RplidarEvent& e);
  void request_scan();
  void tick();
  void remember(const std::uint8_t* bytes, std::size_t n);
  std::uint64_t now_ns() const { return clock_ ? clock_->now_ns() : 0; }

  hal::SerialPort* port_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  RplidarMotorFn motor_ = nullptr;
  void* motor_context_ = nullptr;
  RplidarOptions options_;
  RplidarParser parser_;
  RplidarRevolution revolution_;
  RplidarEvent event_;
  RplidarInfo info_;
  RplidarHealth health_;
  RplidarState state_ = RplidarState::kIdle;
  std::uint64_t sent_ns_ = 0;
  std::uint64_t last_revolution_ns_ = 0;
  char failure_[96] = {0};
  std::uint8_t recent_[16] = {};  // the last bytes received (start-up error message)
  std::uint32_t recent_n_ = 0;    // bytes received outside a stream, all told
  hal::LaserScan scan_;
  bool has_scan_ = false;
  RplidarStats stats_;
  std::uint8_t rx_[1024] = {};
};

}  // namespace hal_serial
