#include "sim/devices/sensor_transport.h"

#include <cmath>
#include <vector>

namespace sim {

namespace {

// Stream index of the byte-fault draws (fw::RandomStream(seed, stream)); apart from the
// localizer's streams so a fault campaign does not change the localizer's draws.
constexpr std::uint64_t kFaultStream = 0x5eb7'f417;

}  // namespace

const char* transport_name(Transport t) {
  switch (t) {
    case Transport::kNone:
      return "none";
    case Transport::kCan:
      return "can";
    case Transport::kSick:
      return "sick";
    case Transport::kHokuyo:
      return "hokuyo";
    case Transport::kRplidar:
      return "rplidar";
  }
  return "?";
}

bool parse_transport(const std::string& name, Transport* out) {
  if (name == "none") {
    *out = Transport::kNone;
  } else if (name == "can") {
    *out = Transport::kCan;
  } else if (name == "sick") {
    *out = Transport::kSick;
  } else if (name == "hokuyo") {
    *out = Transport::kHokuyo;
  } else if (name == "rplidar") {
    *out = Transport::kRplidar;
  } else {
    return false;
  }
  return true;
}

void to_wire_resolution(hal::LaserScan* scan) {
  thread_local std::vector<hal::CanFrame> frames(hal_can::kMaxScanFrames);
  std::size_t n = 0;
  if (!hal_can::encode_scan(*scan, hal_can::EncodeOptions{}, frames.data(), frames.size(), &n).is_ok()) return;
  hal_can::Decoder decoder;
  for (std::size_t i = 0; i < n; ++i) {
    if (decoder.feed(frames[i]) == hal_can::Decoded::kScan) {
      const std::uint32_t id = scan->scan_id;  // the wire carries 16 bits of it
      *scan = decoder.scan();
      scan->scan_id = id;
      return;
    }
  }
}

void to_wire_resolution(hal::Odometry* odom) {
  hal::CanFrame frames[hal_can::kMaxParts];
  std::size_t n = 0;
  if (!hal_can::encode_odometry(*odom, 0, false, frames, hal_can::kMaxParts, &n).is_ok()) return;
  hal_can::Decoder decoder;
  for (std::size_t i = 0; i < n; ++i) {
    if (decoder.feed(frames[i]) == hal_can::Decoded::kOdometry) {
      *odom = decoder.odometry();
      return;
    }
  }
}

namespace {

// The measured values a SICK LMS2xx sends for a scan: mm while the scan's range fits the 13-bit
// field (8.191 m), else cm; at/above range_max, not finite or not representable: "no return".
hal_serial::MeasuredValues sick_values(const hal::LaserScan& scan) {
  hal_serial::MeasuredValues v;
  v.count = static_cast<std::uint16_t>(scan.beam_count < hal_serial::kMaxMeasuredValues ? scan.beam_count
                                                                                     : hal_serial::kMaxMeasuredValues);
  v.unit_mm = scan.range_max <= static_cast<float>(hal_serial::kSickNoReturn) * 0.001f;
  const double per_m = v.unit_mm ? 1000.0 : 100.0;
  for (std::uint16_t b = 0; b < v.count; ++b) {
    const float r = scan.ranges[b];
    const double code = std::round(static_cast<double>(r) * per_m);
    v.values[b] = (!std::isfinite(r) || r < 0.0f || r >= scan.range_max || code >= hal_serial::kSickNoReturn)
                      ? hal_serial::kSickNoReturn
                      : static_cast<std::uint16_t>(code);
  }
  return v;
}

// A clock that says what it is told (the sick round trip stamps the scan with its own time).
class FixedClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return t_ns; }
  std::uint64_t t_ns = 0;
};

}  // namespace

// Named (not anonymous): fields of SensorTransport::Parts, a class with linkage.
namespace transport_detail {

// Scans a serial laser driver delivers carry its own counter; the simulator needs its step index
// back. The device side notes (sample time, index) per scan sent, and a delivered scan (stamped at
// receipt, which in lockstep is its sample time; a Hokuyo's from its ms counter, within tolerance_ns)
// takes the index of its time; scans lost on the way are skipped. A robot's loop sees the driver's
// counter.
class IndexedSickLaser final : public hal::LaserScanSource {
 public:
  void set_inner(hal::LaserScanSource* inner, std::uint64_t tolerance_ns) {
    inner_ = inner;
    tolerance_ns_ = tolerance_ns;
  }
  void sent(std::uint64_t t_ns, std::uint32_t id) { (void)sent_.push_overwrite({t_ns, id}); }
  bool poll(hal::LaserScan* out) override {
    if (!inner_->poll(out)) return false;
    Sent s;
    while (!sent_.empty() && sent_[0].t_ns + tolerance_ns_ < out->timestamp_ns) (void)sent_.pop(&s);
    if (!sent_.empty() && sent_[0].t_ns <= out->timestamp_ns + tolerance_ns_) {
      (void)sent_.pop(&s);
      out->scan_id = s.id;
    }
    return true;
  }
  std::uint32_t fault_bits() const override { return inner_->fault_bits(); }
  std::uint32_t invalid_scans() const override { return inner_->invalid_scans(); }
  std::uint32_t skipped_scans() const override { return inner_->skipped_scans(); }

 private:
  struct Sent {
    std::uint64_t t_ns;
    std::uint32_t id;
  };
  hal::LaserScanSource* inner_ = nullptr;
  std::uint64_t tolerance_ns_ = 0;
  fw::RingBuffer<Sent, 64> sent_;
};

}  // namespace transport_detail

void to_sick_resolution(hal::LaserScan* scan, float fov_rad) {
  if (scan->beam_count == 0) return;
  struct RoundTrip {
    hal_sim::SimSerialPort port;
    FixedClock clock;
    hal_serial::SickLaser laser;
    std::uint8_t bytes[hal_serial::kMaxTelegramData + 16];
  };
  thread_local std::unique_ptr<RoundTrip> rt;
  if (!rt) rt = std::make_unique<RoundTrip>();
  hal_serial::SickLaserOptions so;
  so.fov_rad = fov_rad;
  so.request_continuous = false;
  rt->laser.init(&rt->port, &rt->clock, so);
  const std::size_t n = hal_serial::encode_measured_values(sick_values(*scan), rt->bytes, sizeof(rt->bytes));
  if (n == 0 || !rt->port.device_send(rt->bytes, n)) return;
  rt->clock.t_ns = scan->timestamp_ns;
  const std::uint32_t id = scan->scan_id;
  if (rt->laser.poll(scan)) scan->scan_id = id;
}

namespace transport_detail {

// The wire carries 16 bits of the scan id; the simulator finds a step's truth by the full index,
// so the ids the CanNode delivers are extended (they only grow in a run). A robot's loop sees the
// 16 bits; nothing else of the scan is touched.
class UnwrappedLaser final : public hal::LaserScanSource {
 public:
  explicit UnwrappedLaser(hal::LaserScanSource* inner) : inner_(inner) {}
  bool poll(hal::LaserScan* out) override {
    if (!inner_->poll(out)) return false;
    std::uint32_t id = (last_ & ~0xFFFFu) | (out->scan_id & 0xFFFFu);
    if (have_last_ && id < last_) id += 0x10000u;
    out->scan_id = id;
    last_ = id;
    have_last_ = true;
    return true;
  }
  std::uint32_t fault_bits() const override { return inner_->fault_bits(); }
  std::uint32_t invalid_scans() const override { return inner_->invalid_scans(); }
  std::uint32_t skipped_scans() const override { return inner_->skipped_scans(); }

 private:
  hal::LaserScanSource* inner_;
  std::uint32_t last_ = 0;
  bool have_last_ = false;
};

}  // namespace transport_detail

struct SensorTransport::Parts {
  using UnwrappedLaser = transport_detail::UnwrappedLaser;
  using IndexedSickLaser = transport_detail::IndexedSickLaser;
  hal_sim::SimCanBus bus;
  hal_can::CanNode node;
  UnwrappedLaser laser{&node.laser()};
  hal::CanFrame frames[hal_can::kMaxScanFrames];
  hal_sim::SimSerialPort port;
  hal_serial::RecordingSerialPort recording_port;  // between the driver and its port: the black box
  hal_serial::SickLaser sick;
  IndexedSickLaser sick_laser;
  std::uint8_t bytes[hal_serial::kMaxTelegramData + 16];
  // --transport hokuyo|rplidar (issue 60): device model, its loop port and the driver.
  std::unique_ptr<SerialLidarLink> link;
  hal_serial::SerialBlackBox* serial_box = nullptr;
  std::string device_bytes;
};

SensorTransport::SensorTransport() : parts_(std::make_unique<Parts>()) {}
SensorTransport::~SensorTransport() = default;

bool SensorTransport::init(const TransportOptions& options, const hal::Clock* clock, std::string* err) {
  if (!(options.byte_fault_rate >= 0.0 && options.byte_fault_rate <= 1.0)) {
    *err = "--byte-fault-rate: " + std::to_string(options.byte_fault_rate) + " (expected a probability in [0, 1])";
    return false;
  }
  if (options.byte_fault_rate > 0.0 && options.transport == Transport::kNone) {
    *err = "--byte-fault-rate needs a transport with bytes (--transport can, sick, hokuyo or rplidar)";
    return false;
  }
  if (!laser_model_ok(options, err)) return false;
  options_ = options;
  // A Hokuyo or an RPLIDAR samples the scan at its own angles (its driver gives the geometry).
  const SensorResolution own = options.transport == Transport::kSick ? SensorResolution::kSick
                               : is_serial(options.transport)      ? SensorResolution::kExact
                                                                   : SensorResolution::kCan;
  // The direct path's sensors report what the product's own wire carries (CAN: ranges in mm, angles
  // in µrad, times in µs), as the firmware on a robot only ever sees: `--transport none` and
  // `--transport can` give the same run. Exact floats only when asked for (kExact).
  if (options_.resolution == SensorResolution::kAuto) options_.resolution = own;
  if (options_.transport != Transport::kNone && options_.resolution != own) {
    *err = std::string("--sensor-resolution: --transport ") + transport_name(options.transport) +
           " carries its own wire's values (leave --sensor-resolution out, or say " + transport_name(options.transport) + ")";
    return false;
  }
  init_serial_laser(clock);
  faults_.reseed(options.seed, kFaultStream);
  parts_->node.init(&parts_->bus, clock, options.fd);
  return true;
}

bool SensorTransport::laser_model_ok(const TransportOptions& options, std::string* err) {
  if (options.laser_model.empty()) return true;
  const bool hokuyo = options.transport == Transport::kHokuyo;
  if (!hokuyo && options.transport != Transport::kRplidar) {
    *err = "--laser-model needs --transport hokuyo or rplidar";
    return false;
  }
  if (SerialLidarLink::valid_model(hokuyo ? SerialLidarKind::kHokuyo : SerialLidarKind::kRplidar, options.laser_model)) {
    return true;
  }
  *err = "--laser-model: '" + options.laser_model + "' (expected " +
         (hokuyo ? hokuyo_model_names() : rplidar_model_names()) + " with --transport " + transport_name(options.transport) + ")";
  return false;
}

void SensorTransport::init_serial_laser(const hal::Clock* clock) {
  Parts& p = *parts_;
  if (options_.transport == Transport::kHokuyo || options_.transport == Transport::kRplidar) {
    const SerialLidarKind kind =
        options_.transport == Transport::kHokuyo ? SerialLidarKind::kHokuyo : SerialLidarKind::kRplidar;
    p.link = std::make_unique<SerialLidarLink>(kind, options_.laser_model, &p.port, clock);
    p.recording_port.init(&p.link->device_port(), clock, nullptr);
    p.link->init_driver(&p.recording_port);
    // A Hokuyo's scan time comes from its ms counter mapped by the smallest offset: within 1 ms.
    p.sick_laser.set_inner(&p.link->laser(), kind == SerialLidarKind::kHokuyo ? 2000000u : 0u);
    return;
  }
  hal_serial::SickLaserOptions so;
  so.request_continuous = false;  // the simulated scanner streams from the start
  p.recording_port.init(&p.port, clock, nullptr);
  p.sick.init(&p.recording_port, clock, so);
  p.sick_laser.set_inner(&p.sick, 0);
}

bool SensorTransport::start_serial_laser(std::uint64_t t_ns, bool replay, std::string* err) {
  Parts& p = *parts_;
  if (!p.link || p.link->started()) return true;
  p.recording_port.set_black_box(nullptr);  // on a robot the handshake is over before the ring exists
  const bool ok = p.link->handshake(t_ns, !replay, err);
  p.recording_port.set_black_box(p.serial_box);
  return ok;
}

void SensorTransport::transmit(hal::CanFrame* frames, std::size_t n, std::uint64_t t_ns) {
  for (std::size_t i = 0; i < n; ++i) {
    hal::CanFrame& f = frames[i];
    f.timestamp_ns = t_ns;
    if (frame_index_++ == options_.fault_frame && f.len > 2) {
      f.data[2] ^= 0x01u;
      ++stats_.frames_corrupted;
    }
    std::uint32_t byte = 0;
    std::uint8_t mask = 0;
    bool drop = false;
    if (fault_draw(f.len, &byte, &mask, &drop)) {
      if (drop) continue;
      f.data[byte] ^= mask;
    }
    if (parts_->bus.send(f)) {
      ++stats_.frames_sent;
    } else {
      ++stats_.bus_full;
    }
  }
}

bool SensorTransport::fault_draw(std::size_t len, std::uint32_t* byte, std::uint8_t* mask, bool* drop) {
  if (!(options_.byte_fault_rate > 0.0) || faults_.uniform01() >= options_.byte_fault_rate) return false;
  *drop = (faults_.next_u32() & 1u) != 0 || len == 0;
  if (*drop) {
    ++stats_.frames_dropped;
    return true;
  }
  *byte = faults_.uniform_index(static_cast<std::uint32_t>(len));
  *mask = static_cast<std::uint8_t>(1u << faults_.uniform_index(8));
  ++stats_.frames_corrupted;
  return true;
}

void SensorTransport::to_sensor_resolution(hal::LaserScan* scan) const {
  if (options_.resolution == SensorResolution::kCan) to_wire_resolution(scan);
  if (options_.resolution == SensorResolution::kSick) to_sick_resolution(scan, hal_serial::SickLaserOptions{}.fov_rad);
}

void SensorTransport::to_sensor_resolution(hal::Odometry* odom) const {
  if (options_.resolution == SensorResolution::kCan) to_wire_resolution(odom);
}

void SensorTransport::send_odometry(const hal::Odometry& odom) {
  std::size_t n = 0;
  const fw::Status s = hal_can::encode_odometry(odom, odom_tag_++, options_.fd, parts_->frames, hal_can::kMaxParts, &n);
  if (!s.is_ok()) {
    ++stats_.encode_failed;
    last_encode_error_ = s.message();
    return;
  }
  ++stats_.odometry_sent;
  transmit(parts_->frames, n, odom.timestamp_ns);
}

void SensorTransport::send_scan(const hal::LaserScan& scan) {
  if (options_.transport == Transport::kSick) return send_sick_scan(scan);
  if (is_serial(options_.transport)) return send_serial_scan(scan);
  std::size_t n = 0;
  hal_can::EncodeOptions eo;
  eo.fd = options_.fd;
  const fw::Status s = hal_can::encode_scan(scan, eo, parts_->frames, hal_can::kMaxScanFrames, &n);
  if (!s.is_ok()) {
    ++stats_.encode_failed;
    last_encode_error_ = s.message();
    return;
  }
  ++stats_.scans_sent;
  transmit(parts_->frames, n, scan.timestamp_ns);
}

// Byte-level faults on one scan's bytes (a telegram, an answer, a turn), then onto the wire.
void SensorTransport::put_serial(std::uint8_t* bytes, std::size_t len) {
  std::uint32_t byte = 0;
  std::uint8_t mask = 0;
  bool drop = false;
  if (fault_draw(len, &byte, &mask, &drop)) {
    if (drop) return;
    bytes[byte] ^= mask;
  }
  if (!parts_->port.device_send(bytes, len)) ++stats_.bus_full;
}

// --transport hokuyo|rplidar: the device model's bytes for the scan (the handshake first, once).
void SensorTransport::send_serial_scan(const hal::LaserScan& scan) {
  Parts& p = *parts_;
  if (!p.link->started() && !start_serial_laser(scan.timestamp_ns, false, &stats_.serial_handshake_error)) {
    last_encode_error_ = stats_.serial_handshake_error;
  }
  p.device_bytes.clear();
  p.link->encode_scan(scan, &p.device_bytes);
  if (p.device_bytes.empty()) {
    ++stats_.encode_failed;
    last_encode_error_ = std::string(transport_name(options_.transport)) + ": the simulated device is not streaming";
    return;
  }
  ++stats_.scans_sent;
  p.sick_laser.sent(scan.timestamp_ns, scan.scan_id);
  std::uint8_t* bytes = reinterpret_cast<std::uint8_t*>(p.device_bytes.data());
  if (frame_index_++ == options_.fault_frame && p.device_bytes.size() > 64) {
    bytes[p.device_bytes.size() / 2] ^= 0x01u;  // a byte in the middle: only a sum / check bit can notice
    ++stats_.frames_corrupted;
  }
  put_serial(bytes, p.device_bytes.size());
}

void SensorTransport::send_sick_scan(const hal::LaserScan& scan) {
  const std::size_t len = hal_serial::encode_measured_values(sick_values(scan), parts_->bytes, sizeof(parts_->bytes));
  if (len == 0) {
    ++stats_.encode_failed;
    last_encode_error_ = "sick telegram: scan " + std::to_string(scan.scan_id) + " has no beams";
    return;
  }
  ++stats_.scans_sent;
  ++stats_.telegrams_sent;
  parts_->sick_laser.sent(scan.timestamp_ns, scan.scan_id);
  if (frame_index_++ == options_.fault_frame && len > 8) {
    parts_->bytes[8] ^= 0x01u;  // a range byte: only the CRC-16 can notice
    ++stats_.frames_corrupted;
  }
  put_serial(parts_->bytes, len);
}

bool SensorTransport::send_command(const hal::Command& command, std::uint64_t t_ns, std::string* err) {
  std::size_t n = 0;
  const fw::Status s = hal_can::encode_command(command, options_.fd, parts_->frames, hal_can::kMaxParts, &n);
  if (!s.is_ok()) {
    *err = s.message();
    return false;
  }
  transmit(parts_->frames, n, t_ns);
  return true;
}

bool SensorTransport::inject_frame(const hal::CanFrame& frame) { return parts_->bus.send(frame); }
hal::CommandSource& SensorTransport::commands() { return parts_->node.commands(); }
void SensorTransport::attach_black_box(hal_can::BlackBox* box) { parts_->node.attach_black_box(box); }
void SensorTransport::attach_serial_black_box(hal_serial::SerialBlackBox* box) {
  parts_->serial_box = box;
  parts_->recording_port.set_black_box(box);
}
bool SensorTransport::inject_serial(const std::uint8_t* bytes, std::size_t n) {
  return parts_->port.device_send(bytes, n);
}

hal::LaserScanSource& SensorTransport::laser() {
  if (is_serial(options_.transport)) return parts_->sick_laser;
  return parts_->laser;
}
hal::OdometrySource& SensorTransport::odometry() { return parts_->node.odometry(); }

TransportStats SensorTransport::stats() const {
  TransportStats s = stats_;
  s.decoder = parts_->node.decoder_stats();
  s.node_scans_overflowed = parts_->node.scans_overflowed();
  s.node_odometry_overflowed = parts_->node.odometry_overflowed();
  const hal_serial::SickParserStats& p = parts_->sick.parser_stats();
  s.sick_telegrams = p.telegrams;
  s.sick_crc_errors = p.crc_errors;
  s.sick_bad_length = p.bad_length;
  s.sick_garbage_bytes = p.garbage_bytes;
  s.sick_scans = parts_->sick.stats().scans;
  s.sick_bad_measurements = parts_->sick.stats().bad_measurements;
  s.sick_overwritten = parts_->sick.stats().overwritten;
  if (parts_->link) s.serial = parts_->link->laser().counters();
  return s;
}

}  // namespace sim
