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
  }
  return "?";
}

bool parse_transport(const std::string& name, Transport* out) {
  if (name == "none") {
    *out = Transport::kNone;
  } else if (name == "can") {
    *out = Transport::kCan;
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

struct SensorTransport::Parts {
  hal_sim::SimCanBus bus;
  hal_can::CanNode node;
  UnwrappedLaser laser{&node.laser()};
  hal::CanFrame frames[hal_can::kMaxScanFrames];
};

SensorTransport::SensorTransport() : parts_(std::make_unique<Parts>()) {}
SensorTransport::~SensorTransport() = default;

bool SensorTransport::init(const TransportOptions& options, const hal::Clock* clock, std::string* err) {
  if (!(options.byte_fault_rate >= 0.0 && options.byte_fault_rate <= 1.0)) {
    *err = "--byte-fault-rate: " + std::to_string(options.byte_fault_rate) + " (expected a probability in [0, 1])";
    return false;
  }
  if (options.byte_fault_rate > 0.0 && options.transport == Transport::kNone) {
    *err = "--byte-fault-rate needs a transport with bytes (--transport can)";
    return false;
  }
  options_ = options;
  if (options_.resolution == SensorResolution::kAuto) {
    options_.resolution = options.transport == Transport::kCan ? SensorResolution::kWire : SensorResolution::kExact;
  }
  if (options_.transport == Transport::kCan && options_.resolution != SensorResolution::kWire) {
    *err = "--sensor-resolution exact: the CAN message set carries mm, µrad and µs (use wire, the default with --transport can)";
    return false;
  }
  faults_.reseed(options.seed, kFaultStream);
  parts_->node.init(&parts_->bus, clock, options.fd);
  return true;
}

void SensorTransport::transmit(hal::CanFrame* frames, std::size_t n, std::uint64_t t_ns) {
  for (std::size_t i = 0; i < n; ++i) {
    hal::CanFrame& f = frames[i];
    f.timestamp_ns = t_ns;
    if (frame_index_++ == options_.fault_frame && f.len > 2) {
      f.data[2] ^= 0x01u;
      ++stats_.frames_corrupted;
    }
    if (options_.byte_fault_rate > 0.0 && faults_.uniform01() < options_.byte_fault_rate) {
      if ((faults_.next_u32() & 1u) != 0 || f.len == 0) {
        ++stats_.frames_dropped;
        continue;
      }
      const std::uint32_t byte = faults_.uniform_index(f.len);
      f.data[byte] ^= static_cast<std::uint8_t>(1u << faults_.uniform_index(8));
      ++stats_.frames_corrupted;
    }
    if (parts_->bus.send(f)) {
      ++stats_.frames_sent;
    } else {
      ++stats_.bus_full;
    }
  }
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

hal::LaserScanSource& SensorTransport::laser() { return parts_->laser; }
hal::OdometrySource& SensorTransport::odometry() { return parts_->node.odometry(); }

TransportStats SensorTransport::stats() const {
  TransportStats s = stats_;
  s.decoder = parts_->node.decoder_stats();
  s.node_scans_overflowed = parts_->node.scans_overflowed();
  s.node_odometry_overflowed = parts_->node.odometry_overflowed();
  return s;
}

}  // namespace sim
