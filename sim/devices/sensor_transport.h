// SensorTransport: how the simulated sensors reach the firmware in mml-sim (ArduPilot SITL style:
// the simulator feeds the same frames a real sensor would, so the real drivers run under
// simulation).
//
//   none  scans and odometry go straight into the hal/sim rings (SimLaserSource/SimOdometrySource);
//   can   the device side encodes them with our CAN message set (hal/can codec), sends the frames on
//         the loopback bus of the simulation backend (hal_sim::SimCanBus), and the loop reads them
//         from the firmware's CanNode (decoder, rings, clock mapping) exactly as on the robot.
//   sick  the scans become SICK LMS2xx measured-value telegrams (hal/serial encoder) on the
//         simulation backend's serial port (hal_sim::SimSerialPort) and the loop reads them from
//         the firmware's SickLaser driver (telegram parser, CRC-16, geometry, time stamp at
//         receipt); odometry, which a scanner does not carry, goes straight into its ring.
//   hokuyo, rplidar  (issue 60) the scans become the bytes of a Hokuyo UTM-30LX (SCIP 2.0 "99"
//         answers) or of an RPLIDAR A1 (SCAN samples, one turn of the head per scan), made by the
//         device models of mml-hokuyodev / mml-rplidardev (sim/devices/serial_lidar_link.h), and the
//         loop reads them from the firmware's HokuyoLaser / RplidarLaser, after their start-up
//         handshake answered by the simulated device at the first scan's time. The device samples
//         the simulated scan at its own angles (1081 steps over 270°; ~364 samples a turn resampled
//         by the driver onto 360 beams): the firmware sees that unit's geometry. An RPLIDAR turn
//         reaches the firmware when the next one begins: one scan later.
//
// The wire is lossy (CAN: ranges in the range unit, 1 mm up to 65 m; angles in µrad / 0.1 µrad;
// odometry in mm and µrad; times in µs. SICK: ranges in mm up to 8.191 m, else cm; the geometry
// the driver knows, ±fov/2), so with `can` or `sick` the simulated sensors report at that wire's
// resolution: to_wire_resolution() / to_sick_resolution() apply it with the codec or driver itself
// (encode, then decode; idempotent). The direct path keeps the exact floats by default (all
// figures of earlier runs unchanged) and takes the same resolution with `--sensor-resolution
// can|sick`; then, with `--timing none`, the driver path and the direct one give the same
// steps.csv byte for byte (sim_transport_*_test).
//
// Faults at the byte level (`--byte-fault-rate P`): every frame on its way to the bus is, with
// probability P (seeded stream), either dropped or has one bit of one data byte flipped (half each);
// for `sick` the unit is one telegram. The decoder / parser drops and counts the affected
// scan/record (CRC, lost segment, malformed); nothing crashes; TransportStats reports both sides.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "firmware/base/rng.h"
#include "hal/clock.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "hal/sensor_io.h"
#include "hal_can/can_node.h"
#include "hal_can/codec.h"
#include "hal_serial/recording_serial_port.h"
#include "hal_serial/serial_black_box.h"
#include "hal_serial/sick_laser.h"
#include "hal_sim/sim_can_bus.h"
#include "hal_sim/sim_serial_port.h"
#include "sim/devices/serial_lidar_link.h"

namespace sim {

enum class Transport : std::uint8_t { kNone, kCan, kSick, kHokuyo, kRplidar };
// A laser on a serial port (sick, hokuyo, rplidar): bytes a black box records as serial lines.
inline bool is_serial(Transport t) { return t == Transport::kSick || t == Transport::kHokuyo || t == Transport::kRplidar; }
// What the simulated sensors report: exact floats, or the values a wire carries. kAuto: the
// transport's own (the only possible one with can / sick); with none, the CAN wire's (the product's
// wire: a robot's firmware never sees more than it carries), so none and can give the same run.
enum class SensorResolution : std::uint8_t { kAuto, kExact, kCan, kSick };
const char* transport_name(Transport t);
// false for an unknown name (expected none, can, sick, hokuyo or rplidar).
bool parse_transport(const std::string& name, Transport* out);

struct TransportOptions {
  Transport transport = Transport::kNone;
  bool fd = false;                // CAN FD frames instead of classic
  SensorResolution resolution = SensorResolution::kAuto;
  double byte_fault_rate = 0.0;   // per frame, in [0, 1]: drop it or flip one bit of one data byte
  std::uint64_t seed = 1;         // fault stream
  // Test hook: flip one bit of byte 2 (a range byte of a scan segment) of exactly this CAN frame,
  // or of byte 8 (a range byte) of this SICK telegram (0-based count of frames / telegrams sent);
  // -1 = off.
  std::int64_t fault_frame = -1;
  // A serial laser: odometry and operator commands on the CAN wire (the CanNode), as a robot with a serial
  // laser and `odometry = socketcan:IFACE` has them; off, odometry goes straight into its ring.
  // The black box turns it on (issue 60): a replay needs every input on a wire it recorded.
  bool sick_odometry_on_can = false;
  // kHokuyo / kRplidar: the unit the device model plays (--laser-model; empty: utm-30lx / a1). A
  // replay's start-up handshake is answered by it, so it must be the recorded unit.
  std::string laser_model;
};

struct TransportStats {
  // Device side.
  std::uint64_t scans_sent = 0, odometry_sent = 0, frames_sent = 0;
  std::uint64_t encode_failed = 0;  // messages the encoder refused (named in last_encode_error)
  std::uint64_t bus_full = 0;       // frames the loopback bus refused (its queue was full)
  std::uint64_t frames_dropped = 0, frames_corrupted = 0;  // injected byte-level faults
  // Firmware side (CanNode's decoder).
  hal_can::DecoderStats decoder;
  std::uint32_t node_scans_overflowed = 0, node_odometry_overflowed = 0;
  // --transport sick: telegrams sent, and the firmware's parser and driver.
  std::uint64_t telegrams_sent = 0;
  std::uint32_t sick_telegrams = 0, sick_crc_errors = 0, sick_bad_length = 0, sick_garbage_bytes = 0;
  std::uint32_t sick_scans = 0, sick_bad_measurements = 0, sick_overwritten = 0;
  // --transport hokuyo|rplidar: the driver's common counters, and a handshake that failed.
  hal_serial::SerialLaserCounters serial;
  std::string serial_handshake_error;
};

// The value a simulated sensor reports: the message as the wire carries it (encode + decode with
// the hal/can codec; idempotent). A message the encoder refuses (impossible geometry, no beams) is
// left as it is (the CAN path counts it in encode_failed and does not send it).
void to_wire_resolution(hal::LaserScan* scan);
void to_wire_resolution(hal::Odometry* odom);
// The scan a SICK LMS2xx with this field of view reports for it, through the telegram encoder and
// the firmware's SickLaser (time stamp: the scan's own). Odometry is not a scanner's.
void to_sick_resolution(hal::LaserScan* scan, float fov_rad);

class SensorTransport {
 public:
  SensorTransport();
  ~SensorTransport();
  SensorTransport(const SensorTransport&) = delete;
  SensorTransport& operator=(const SensorTransport&) = delete;

  // false with *err for a bad option. `clock` is the simulation clock the CanNode reads.
  bool init(const TransportOptions& options, const hal::Clock* clock, std::string* err);
  Transport transport() const { return options_.transport; }
  // The simulated sensors' resolution (resolved at init) applied to a scan / an odometry sample.
  void to_sensor_resolution(hal::LaserScan* scan) const;
  void to_sensor_resolution(hal::Odometry* odom) const;
  // Whether odometry and commands travel on the CAN wire (can; sick with sick_odometry_on_can) or
  // straight into their ring / queue.
  bool carries_odometry() const {
    return options_.transport == Transport::kCan || (is_serial(options_.transport) && options_.sick_odometry_on_can);
  }

  // kCan: encode and send (frames stamped with the message's time on the simulation clock: the
  // device transmits at the sample time, zero latency); kSick: scans only, as telegrams on the
  // serial port (the driver stamps them at receipt). Not used for kNone.
  void send_odometry(const hal::Odometry& odom);
  void send_scan(const hal::LaserScan& scan);

  // kCan: an operator command on the wire (hal/can codec), stamped t_ns (issue 60); false with *err
  // when the encoder refuses it (a NaN hint): the firmware never sees what the wire cannot carry.
  bool send_command(const hal::Command& command, std::uint64_t t_ns, std::string* err);
  // kCan: a frame as it was received (a black box replay): onto the loopback bus, unchanged.
  bool inject_frame(const hal::CanFrame& frame);
  // kCan: the CanNode's command queue, and its black box (null = none).
  hal::CommandSource& commands();
  void attach_black_box(hal_can::BlackBox* box);
  // A serial laser (kSick, kHokuyo, kRplidar): the bytes its driver reads from (and writes to) its
  // port recorded in `box` (null = none), and bytes as they were received (a black box replay)
  // queued for it; false if the port is full.
  void attach_serial_black_box(hal_serial::SerialBlackBox* box);
  bool inject_serial(const std::uint8_t* bytes, std::size_t n);
  // kHokuyo / kRplidar: the driver's start-up handshake at t_ns against the simulated device, not
  // recorded (send_scan runs it before the first scan). A replay runs it before the file's first
  // serial line, at that line's time, and the device answers nothing after it (every later byte is
  // the file's). No-op for the other transports and once started; false with *err if it failed.
  bool start_serial_laser(std::uint64_t t_ns, bool replay, std::string* err);

  // The sources the localization loop reads for kCan (the CanNode's) and a serial laser (its driver's scans).
  hal::LaserScanSource& laser();
  hal::OdometrySource& odometry();

  TransportStats stats() const;
  const std::string& last_encode_error() const { return last_encode_error_; }

 private:
  void transmit(hal::CanFrame* frames, std::size_t n, std::uint64_t t_ns);
  static bool laser_model_ok(const TransportOptions& options, std::string* err);
  void init_serial_laser(const hal::Clock* clock);
  void send_serial_scan(const hal::LaserScan& scan);
  void send_sick_scan(const hal::LaserScan& scan);
  void put_serial(std::uint8_t* bytes, std::size_t len);
  bool fault_draw(std::size_t len, std::uint32_t* byte, std::uint8_t* mask, bool* drop);

  TransportOptions options_;
  fw::RandomStream faults_{1, 0};
  std::uint8_t odom_tag_ = 0;
  std::int64_t frame_index_ = 0;
  TransportStats stats_;
  std::string last_encode_error_;
  // Large (the bus queue, the node's rings, one scan's frames): on the host heap, created once.
  struct Parts;
  std::unique_ptr<Parts> parts_;
};

}  // namespace sim
