// Sources and sinks the localization loop uses. A backend (sim, socketcan, serial) implements
// them; the firmware sees only these interfaces. All calls are non-blocking: poll() returns
// false when nothing is pending.
#pragma once

#include <cstdint>

#include "hal/msg/command.h"
#include "hal/msg/health.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "hal/msg/pose_estimate.h"

namespace hal {

class LaserScanSource {
 public:
  virtual ~LaserScanSource() = default;
  // Copies the next complete scan into *out; false if none is pending.
  virtual bool poll(LaserScan* out) = 0;
  // Link faults of the source (HealthFault bits, e.g. laser-disconnected) and the number of scans
  // it received intact but rejected as impossible; the loop puts both in the health frame.
  virtual std::uint32_t fault_bits() const { return 0; }
  virtual std::uint32_t invalid_scans() const { return 0; }
  // Scans received intact but replaced by a newer one before poll() handed them out (the firmware
  // skips to the newest scan when a step is slower than the sensor); the loop adds them to the
  // health frame's dropped_scans. Sources that count such losses in their own health path (CanNode)
  // leave this at 0.
  virtual std::uint32_t skipped_scans() const { return 0; }
};

class OdometrySource {
 public:
  virtual ~OdometrySource() = default;
  virtual bool poll(Odometry* out) = 0;
};

class PoseSink {
 public:
  virtual ~PoseSink() = default;
  virtual void publish(const PoseEstimate& estimate) = 0;
  virtual void publish_health(const Health& health) = 0;
  // The answer to an operator command (COMMAND_REPLY on CAN); sinks without a reply channel drop it.
  virtual void publish_reply(const CommandReply& reply) { (void)reply; }
};

// Operator commands (SET_POSE_HINT, SELECT_MAP, DUMP_LOG) as they arrive.
class CommandSource {
 public:
  virtual ~CommandSource() = default;
  virtual bool poll(Command* out) = 0;
};

}  // namespace hal
