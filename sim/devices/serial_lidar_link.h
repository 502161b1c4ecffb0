// SerialLidarLink: the device side of mml-sim's --transport hokuyo|rplidar (issue 60). The
// simulated scans become the bytes of a real unit — SCIP 2.0 answers of a Hokuyo UTM-30LX
// (HokuyoDevice) or SCAN samples of an RPLIDAR A1 (RplidarDevice), the encoders of mml-hokuyodev /
// mml-rplidardev — on the hal/sim serial port, and the firmware's HokuyoLaser / RplidarLaser reads
// them. The device answers what the driver writes (its start-up handshake, a handshake again after
// a silence) at once, inside the driver's write().
//
// The start-up handshake runs once, at the time of the first scan (handshake(t_ns)): the driver's
// clock reads t_ns throughout it, so a recording and its replay start the driver in the same state.
// It is not in the black box (on a robot it is over before the ring exists); a replay runs it
// against the simulated device and then stops the device answering (answer_after_handshake false):
// every later byte, handshakes again included, comes from the file.
#pragma once

#include <cstdint>
#include <string>

#include "hal/clock.h"
#include "hal/msg/laser_scan.h"
#include "hal/serial_port.h"
#include "hal_serial/hokuyo_laser.h"
#include "hal_serial/rplidar_laser.h"
#include "hal_sim/sim_serial_port.h"
#include "sim/devices/hokuyo_device.h"
#include "sim/devices/rplidar_device.h"

namespace sim {

enum class SerialLidarKind : std::uint8_t { kHokuyo, kRplidar };

// The driver's clock: the simulation clock, or a fixed time during the start-up handshake.
class HandshakeClock final : public hal::Clock {
 public:
  explicit HandshakeClock(const hal::Clock* inner) : inner_(inner) {}
  std::uint64_t now_ns() const override { return fixed_ ? t_ns_ : inner_->now_ns(); }
  void fix(std::uint64_t t_ns) { fixed_ = true; t_ns_ = t_ns; }
  void release() { fixed_ = false; }

 private:
  const hal::Clock* inner_;
  bool fixed_ = false;
  std::uint64_t t_ns_ = 0;
};

// hal::SerialPort between the driver (through the recording port) and the hal/sim serial port:
// reads come from the wire, writes go to the simulated device, whose answers go onto the wire.
class DeviceLoopPort final : public hal::SerialPort {
 public:
  DeviceLoopPort(SerialLidarKind kind, hal_sim::SimSerialPort* wire, HokuyoDevice* hokuyo, RplidarDevice* rplidar)
      : kind_(kind), wire_(wire), hokuyo_(hokuyo), rplidar_(rplidar) {}
  long read(std::uint8_t* buf, std::size_t len) override { return wire_->read(buf, len); }
  long write(const std::uint8_t* buf, std::size_t len) override;
  void set_answering(bool on) { answering_ = on; }
  std::uint64_t refused() const { return refused_; }

 private:
  SerialLidarKind kind_;
  hal_sim::SimSerialPort* wire_;
  HokuyoDevice* hokuyo_;
  RplidarDevice* rplidar_;
  bool answering_ = true;
  std::uint64_t refused_ = 0;
  std::string answer_;
};

class SerialLidarLink {
 public:
  // `model`: a HokuyoModel / RplidarModel name (find_hokuyo_model / find_rplidar_model); empty: the
  // default unit (utm-30lx, a1). False from valid_model for a name the kind does not know.
  SerialLidarLink(SerialLidarKind kind, const std::string& model, hal_sim::SimSerialPort* wire, const hal::Clock* clock);
  static bool valid_model(SerialLidarKind kind, const std::string& model);
  SerialLidarKind kind() const { return kind_; }
  // The port the driver is to write to and read from (wrap it in a recording port first).
  hal::SerialPort& device_port() { return loop_; }
  // Initialises the driver on `port` (the recording port over device_port()).
  void init_driver(hal::SerialPort* port);
  hal_serial::SerialLaser& laser();
  // The start-up handshake at t_ns against the simulated device; false with *err (the driver's
  // description) if the driver is not streaming after it. answer_after_handshake false (a replay):
  // the device stays silent from then on.
  bool handshake(std::uint64_t t_ns, bool answer_after_handshake, std::string* err);
  bool started() const { return started_; }
  // One scan as the device sends it (Hokuyo: one "99" answer stamped with the scan's time in ms;
  // RPLIDAR: the samples of one turn of the head, the next turn's start flag ending it); the bytes
  // are appended to *out, empty while the device is not streaming.
  void encode_scan(const hal::LaserScan& scan, std::string* out);
  // The unit played (for messages): the model's name.
  const char* model_name() const;

 private:
  SerialLidarKind kind_;
  HokuyoDevice hokuyo_dev_;
  RplidarDevice rplidar_dev_;
  HandshakeClock clock_;
  DeviceLoopPort loop_;
  hal_serial::HokuyoLaser hokuyo_;
  hal_serial::RplidarLaser rplidar_;
  bool started_ = false;
};

}  // namespace sim
